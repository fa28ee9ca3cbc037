"""The parsed form of a script and how each part evaluates (BehaviorTree.CPP's
``scripting/operators.hpp``, in our own types).

Arithmetic (``+ - * /``) gives a real, as BehaviorTree.CPP's doubles do; ``& | ^`` take
integers (an integral real too) and ``~`` truncates; ``&& || !`` and comparisons give a
Bool. Both sides of ``&&`` and ``||`` are evaluated (no short-circuit, as there). A
comparison of Text with a Number reads the Text as a number (``'3' == 3``); ``==`` and
``!=`` on numbers allow a float epsilon (1.19e-7). ``..`` joins Text with Text or a Number.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from engine.blackboard import MISSING
from engine.script.errors import ScriptNameError, ScriptRunError, ScriptTypeError
from engine.script.values import (
    ScriptEnv,
    ValueProblem,
    assignable,
    describe,
    integer,
    is_number,
    text_of,
    text_to_number,
    truth,
)

__all__ = ["Expr", "Literal", "Name", "Unary", "Binary", "Compare", "Ternary", "Assign"]

# std::numeric_limits<float>::epsilon(): how close two numbers are to be equal.
EQUAL_EPSILON = 1.1920928955078125e-07

Where = Callable[[int], tuple[int, int]]  # an offset -> (line, column)


@dataclass(frozen=True)
class Expr:
    """A part of a script; ``pos`` is the offset it is reported at."""

    pos: int

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        raise NotImplementedError

    def fail(self, where: Where, why: str, kind: type[ScriptRunError] = ScriptTypeError) -> Any:
        """Raise ``kind`` for this part, at its line and column."""
        raise kind(why, *where(self.pos)) from None


@dataclass(frozen=True)
class Literal(Expr):
    """A number, a string or true/false."""

    value: Any

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        return self.value


@dataclass(frozen=True)
class Name(Expr):
    """An enum value, else an entry (``@name``: at the top of the tree)."""

    name: str

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        if self.name in env.enums:
            return env.enums[self.name]
        value = env.read(self.name)
        if value is MISSING or value is None:
            why = "has no value yet" if env.exists(self.name) else "does not exist"
            self.fail(where, f"the entry {self.name!r} {why}", ScriptNameError)
        return value


def _operand(expr: Expr, env: ScriptEnv, where: Where, op: str, side: str) -> Any:
    value = expr.evaluate(env, where)
    if value is None:
        expr.fail(where, f"the {side} operand of {op!r} has no value")
    return value


@dataclass(frozen=True)
class Unary(Expr):
    """``-x``, ``~x`` or ``!x``."""

    op: str
    operand: Expr

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        value = _operand(self.operand, env, where, self.op, "right")
        if not is_number(value):
            self.fail(where, f"{self.op!r} expected a Number or a Bool, got {describe(value)}")
        if self.op == "!":
            return value == 0
        if self.op == "-":
            return -float(value)
        if not -(2.0**63) <= value <= 2.0**63:
            self.fail(where, f"'~' expected a 64-bit integer, got {describe(value)}")
        return float(~int(value))


_ARITHMETIC: dict[str, Callable[[float, float], float]] = {
    "+": operator.add,
    "-": operator.sub,
    "*": operator.mul,
    "/": operator.truediv,
}
_BITWISE: dict[str, Callable[[int, int], int]] = {
    "&": operator.and_,
    "|": operator.or_,
    "^": operator.xor,
}
_EXPECTED = {
    "+": "two Numbers or two Texts",
    "..": "a Text and a Text or a Number",
    "&&": "two Numbers or Bools",
    "||": "two Numbers or Bools",
    **dict.fromkeys("-*/", "two Numbers"),
    **dict.fromkeys("&|^", "two integers"),
}


def arithmetic(op: str, left: float, right: float) -> float:
    """``left op right`` for ``+ - * /``, as reals.

    Raises:
        ValueProblem: a division by zero.
    """
    if op == "/" and right == 0:
        why = f"division by zero ({describe(left)} / {describe(right)})"
        raise ValueProblem(why, ScriptRunError)
    return _ARITHMETIC[op](float(left), float(right))


@dataclass(frozen=True)
class Binary(Expr):
    """``left op right`` for the arithmetic, bitwise, logical and ``..`` operators."""

    op: str
    left: Expr
    right: Expr

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        left = _operand(self.left, env, where, self.op, "left")
        right = _operand(self.right, env, where, self.op, "right")
        try:
            return self._apply(left, right)
        except ValueProblem as exc:
            return self.fail(where, f"{self.op!r}: {exc}", exc.kind)

    def _apply(self, left: Any, right: Any) -> Any:
        op = self.op
        numbers = is_number(left) and is_number(right)
        if numbers and op in _ARITHMETIC:
            return arithmetic(op, left, right)
        if numbers and op in _BITWISE:
            return float(_BITWISE[op](integer(left), integer(right)))
        if numbers and op in ("&&", "||"):
            return bool(left) and bool(right) if op == "&&" else bool(left) or bool(right)
        if op == "+" and isinstance(left, str) and isinstance(right, str):
            return left + right
        texts = isinstance(left, str) or isinstance(right, str)
        joinable = all(isinstance(v, str) or is_number(v) for v in (left, right))
        if op == ".." and texts and joinable:
            return text_of(left) + text_of(right)
        raise ValueProblem(f"expected {_EXPECTED[op]}, got {describe(left)} and {describe(right)}")


_ORDER: dict[str, Callable[[Any, Any], bool]] = {
    "<": operator.lt,
    ">": operator.gt,
    "<=": operator.le,
    ">=": operator.ge,
}


def compare(op: str, left: Any, right: Any, env: ScriptEnv) -> bool:
    """``left op right`` for one comparison operator.

    Raises:
        ValueProblem: the two cannot be compared.
    """
    if isinstance(left, str) and is_number(right):
        left = text_to_number(left, env.enums)
    elif is_number(left) and isinstance(right, str):
        right = text_to_number(right, env.enums)
    if is_number(left) and is_number(right):
        left, right = float(left), float(right)
        if op in ("==", "!="):
            return (abs(left - right) <= EQUAL_EPSILON) == (op == "==")
    elif not (isinstance(left, str) and isinstance(right, str)):
        raise ValueProblem(f"cannot compare {describe(left)} with {describe(right)}")
    if op in ("==", "!="):
        return (left == right) == (op == "==")
    return _ORDER[op](left, right)


@dataclass(frozen=True)
class Compare(Expr):
    """A comparison, chained: ``a < b < c`` is ``a < b`` and ``b < c``, each side read once."""

    ops: tuple[str, ...]
    operands: tuple[Expr, ...]

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        left = _operand(self.operands[0], env, where, self.ops[0], "left")
        for op, expr in zip(self.ops, self.operands[1:], strict=True):
            right = _operand(expr, env, where, op, "right")
            try:
                holds = compare(op, left, right, env)
            except ValueProblem as exc:
                self.fail(where, f"{op!r}: {exc}")
            if not holds:
                return False
            left = right
        return True


@dataclass(frozen=True)
class Ternary(Expr):
    """``condition ? then : otherwise``; only the branch taken is evaluated."""

    condition: Expr
    then: Expr
    otherwise: Expr

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        value = _operand(self.condition, env, where, "?", "left")
        try:
            taken = truth(value)
        except ValueProblem as exc:
            return self.fail(where, f"'?': {exc}")
        return (self.then if taken else self.otherwise).evaluate(env, where)


@dataclass(frozen=True)
class Assign(Expr):
    """``name := value`` (creates the entry), ``name = value`` (the entry must exist) and
    ``+= -= *= /=`` (the entry must hold a value); the value is the one stored.
    """

    op: str
    name: str
    value: Expr

    def evaluate(self, env: ScriptEnv, where: Where) -> Any:
        if self.name in env.enums:
            self.fail(where, f"{self.name!r} is an enum value, not an entry", ScriptNameError)
        if self.op != ":=" and not env.exists(self.name):
            self.fail(
                where,
                f"the entry {self.name!r} does not exist (':=' creates one, {self.op!r} does not)",
                ScriptNameError,
            )
        current = env.read(self.name)
        if self.op not in (":=", "=") and (current is MISSING or current is None):
            self.fail(
                where, f"the entry {self.name!r} has no value for {self.op!r}", ScriptNameError
            )
        value = _operand(self.value, env, where, self.op, "right")
        try:
            if self.op not in (":=", "="):
                value = self._combine(current, value)
            stored = assignable(value, env.declared(self.name), current, env.enums)
            env.write(self.name, stored)
        except ValueProblem as exc:
            return self.fail(where, f"{self.op!r} to the entry {self.name!r}: {exc}", exc.kind)
        return stored

    def _combine(self, current: Any, value: Any) -> Any:
        op = self.op[0]
        if is_number(value) and is_number(current):
            return arithmetic(op, current, value)
        if isinstance(value, str) and isinstance(current, str) and op == "+":
            return current + value
        expected = "two Numbers or two Texts" if op == "+" else "two Numbers"
        raise ValueProblem(f"expected {expected}, got {describe(current)} and {describe(value)}")
