"""Script values as the engine types them, and where a script reads and writes them.

BehaviorTree.CPP's scripts hold 64-bit integers, doubles and strings (its ``true`` is the
double 1.0). Here a value is what the engine's parameters hold: an ``int`` or a ``float``
(Number), a ``bool`` (Bool: ``true``, a comparison, ``!``, ``&&``, ``||``), a ``str``
(Text), or any other parameter value read from an entry (a Pose...), which operators refuse.
A bool counts as the number 1 or 0 wherever BehaviorTree.CPP would use its double.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from typing import Any

from engine.blackboard import MISSING, Blackboard, BlackboardError
from engine.script.errors import ScriptRunError, ScriptTypeError
from engine.types import ParamType, check_value, type_of_value

__all__ = [
    "ScriptEnv",
    "ValueProblem",
    "as_bool",
    "assignable",
    "describe",
    "is_number",
    "text_of",
    "text_to_number",
    "truth",
]

ROOT_PREFIX = "@"
# Text that reads as a number: what BehaviorTree.CPP's from_chars takes, whole.
_NUMBER_TEXT = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?")
_BOOL_TEXT = {"true": True, "false": False, "True": True, "False": False, "1": True, "0": False}
_BOOL_TEXT |= {"TRUE": True, "FALSE": False}
_INT64 = 2**63


class ValueProblem(Exception):
    """A value that does not fit; the evaluator adds the place (line, column).

    Attributes:
        kind: the error it becomes (a type error unless told).
    """

    def __init__(self, message: str, kind: type[ScriptRunError] = ScriptTypeError) -> None:
        super().__init__(message)
        self.kind = kind


def is_number(value: Any) -> bool:
    """A Number or a Bool (BehaviorTree.CPP's booleans are numbers)."""
    return isinstance(value, (int, float))


def describe(value: Any) -> str:
    """A value for messages, with its engine type: ``Number 3``, ``Text 'a'``, ``Bool true``."""
    if isinstance(value, bool):
        return f"Bool {'true' if value else 'false'}"
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{type_of_value(value).value} {text}"


def text_of(value: Any) -> str:
    """A Text or a Number as ``..`` joins it: an integer's digits, a real with six decimals
    (C++'s ``std::to_string``), a Bool as ``true`` / ``false``.
    """
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    return f"{value:f}"


def text_to_number(text: str, enums: Mapping[str, int]) -> float:
    """A Text compared with or assigned to a Number: ``true``/``false``, an enum value or the
    number it spells.

    Raises:
        ValueProblem: none of these.
    """
    if text in ("true", "false"):
        return 1.0 if text == "true" else 0.0
    if text in enums:
        return float(enums[text])
    if _NUMBER_TEXT.fullmatch(text):
        return float(text)
    raise ValueProblem(f"expected a number, true, false or an enum value, got Text {text!r}")


def truth(value: Any) -> bool:
    """The condition of ``?:``: a Number not 0, a Bool, a Text that is not empty."""
    if is_number(value):
        return bool(value != 0)
    if isinstance(value, str):
        return value != ""
    raise ValueProblem(f"expected a Number, a Bool or a Text as a condition, got {describe(value)}")


def as_bool(value: Any) -> bool:
    """The outcome of a ScriptCondition: a Bool, a Number (not 0) or a Text true/false/1/0."""
    if is_number(value):
        return bool(value != 0)
    if isinstance(value, str) and value in _BOOL_TEXT:
        return _BOOL_TEXT[value]
    raise ValueProblem(f"expected true or false, got {describe(value)}")


def integer(value: Any) -> int:
    """A Number that is a 64-bit integer (the operands of ``& | ^``)."""
    if is_number(value) and float(value).is_integer() and -_INT64 <= value < _INT64:
        return int(value)
    raise ValueProblem(f"expected an integer, got {describe(value)}")


def _to_number(value: Any, enums: Mapping[str, int]) -> float | int:
    if isinstance(value, str):
        return text_to_number(value, enums)
    if is_number(value):
        return value
    raise ValueProblem(f"expected a Number, got {describe(value)}")


def _to_bool(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if is_number(value) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value in _BOOL_TEXT:
        return _BOOL_TEXT[value]
    raise ValueProblem(f"expected a Bool (true, false, 1 or 0), got {describe(value)}")


def assignable(
    value: Any, declared: ParamType | None, current: Any, enums: Mapping[str, int]
) -> Any:
    """``value`` as an entry of type ``declared`` (or, when undeclared, of ``current``'s type)
    stores it; BehaviorTree.CPP's rule that an entry keeps the type it was created with.

    A Number entry takes a Number, a Bool (1 or 0) or a Text that reads as a number; one that
    holds an integer and is not declared keeps integers only (as a C++ ``int64`` entry does).
    A Bool entry takes a Bool, 1, 0 or a Text true/false/1/0. A Text entry takes only Text.

    Raises:
        ValueProblem: the value does not convert; the message says what was expected.
    """
    ptype = declared
    if ptype is None and current is not MISSING and current is not None:
        ptype = type_of_value(current)
    if ptype is None or ptype is ParamType.ANY:
        return value
    if ptype in (ParamType.NUMBER, ParamType.DURATION):
        number = _to_number(value, enums)
        if not math.isfinite(number):
            raise ValueProblem(f"expected a finite number, got {number}")
        keep_int = declared is None and isinstance(current, int) and not isinstance(current, bool)
        if not keep_int:
            return float(number)
        if not float(number).is_integer():
            raise ValueProblem(f"expected an integer (the entry holds one), got {number!r}")
        return int(number)
    if ptype is ParamType.BOOL:
        return _to_bool(value)
    if check_value(ptype, value):
        return value
    raise ValueProblem(f"expected {ptype.value}, got {describe(value)}")


class ScriptEnv:
    """Where a script reads and writes: the tree's blackboard, seen from one scope.

    Args:
        blackboard: the tree's blackboard.
        enums: names that read as integers (BehaviorTree.CPP's scripting enums); a name here
            is never an entry.
        key: a name in the script -> its blackboard key (a subtree instance's scope, as
            ``engine.instances.Scope.key``); ``@name`` is always the key ``name`` (the
            top of the tree, BehaviorTree.CPP's root blackboard).
        writer: the node id the writes are reported with.
    """

    def __init__(
        self,
        blackboard: Blackboard,
        enums: Mapping[str, int] | None = None,
        key: Callable[[str], str] | None = None,
        writer: str = "",
    ) -> None:
        self.blackboard = blackboard
        self.enums: Mapping[str, int] = dict(enums or {})
        self._key = key
        self.writer = writer

    def key_of(self, name: str) -> str:
        """The blackboard key of a name as the script writes it (``@name``: at the top)."""
        if name.startswith(ROOT_PREFIX):
            return name[len(ROOT_PREFIX) :]
        return self._key(name) if self._key is not None else name

    def exists(self, name: str) -> bool:
        """The entry exists: it has a value or a declared type (then ``=`` may write it)."""
        key = self.key_of(name)
        return key in self.blackboard or self.blackboard.type_of(key) is not None

    def read(self, name: str) -> Any:
        """The entry's value, MISSING when it has none."""
        return self.blackboard.get(self.key_of(name), MISSING)

    def declared(self, name: str) -> ParamType | None:
        return self.blackboard.type_of(self.key_of(name))

    def write(self, name: str, value: Any) -> None:
        """Write an entry (already converted by :func:`assignable`).

        Raises:
            ValueProblem: the blackboard refused it.
        """
        try:
            self.blackboard.set(self.key_of(name), value, self.writer)
        except BlackboardError as exc:
            raise ValueProblem(str(exc)) from None
