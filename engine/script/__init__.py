"""BehaviorTree.CPP's scripting language, parsed and run by the engine (no ``eval``).

What its ``Script``, ``ScriptCondition`` and pre/post conditions hold::

    counter := 0; counter += 1; ready = counter >= 3 && @mode == 'auto'

``:=`` creates an entry, ``=`` writes one that exists (else fails), ``+= -= *= /=`` update
one; ``?:``, ``|| && !``, chained comparisons, ``| ^ & ~``, ``+ - * /``, ``..`` (join text),
integers (``0x1F`` too), reals, single-quoted strings, ``true`` / ``false``, ``@name`` (the
entry at the top of the tree) and enum names. A script's value is its last statement's.

:func:`parse_script` checks a script once (a :class:`ScriptSyntaxError` names the line and
column); :meth:`Script.run` runs it against a :class:`ScriptEnv` (a blackboard seen from a
scope, and the enums); a run's failure is a :class:`ScriptRunError` (a missing entry, a
value of the wrong type, a division by zero) at the line and column of the operator.
How values are typed: :mod:`engine.script.values`; the operators:
:mod:`engine.script.expressions`; the grammar: :mod:`engine.script.parser`.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, fields
from typing import Any

from engine.blackboard import Blackboard
from engine.script.errors import (
    ScriptError,
    ScriptNameError,
    ScriptRunError,
    ScriptSyntaxError,
    ScriptTypeError,
    line_column,
)
from engine.script.expressions import Assign, Expr, Name
from engine.script.parser import parse_statements
from engine.script.values import ScriptEnv, ValueProblem, as_bool

__all__ = [
    "Script",
    "ScriptNames",
    "ScriptEnv",
    "ScriptError",
    "ScriptNameError",
    "ScriptRunError",
    "ScriptSyntaxError",
    "ScriptTypeError",
    "parse_script",
    "run_script",
    "script_names",
]


@dataclass(frozen=True)
class Script:
    """A parsed script: its text and its statements.

    Attributes:
        text: the script as written.
        statements: its statements, in order.
    """

    text: str
    statements: tuple[Expr, ...]

    def _where(self, offset: int) -> tuple[int, int]:
        return line_column(self.text, offset)

    def run(self, env: ScriptEnv) -> Any:
        """Run every statement; the value of the last.

        Raises:
            ScriptRunError: a statement failed (the ones before it have written their entries).
        """
        value: Any = None
        for statement in self.statements:
            value = statement.evaluate(env, self._where)
        return value

    def check(self, env: ScriptEnv) -> bool:
        """Run it as a condition (BehaviorTree.CPP's ScriptCondition): true or false.

        Raises:
            ScriptRunError: a statement failed, or the value is not true/false, a Number or a
                Text true/false/1/0.
        """
        value = self.run(env)
        try:
            return as_bool(value)
        except ValueProblem as exc:
            line, column = self._where(self.statements[-1].pos)
            raise ScriptTypeError(f"the script's value: {exc}", line, column) from None


@dataclass(frozen=True)
class ScriptNames:
    """The entries a script reads and writes, for validation (``@`` names left out).

    Attributes:
        reads: names read before the script itself has written them, in order.
        writes: every name it may write (in any branch).
        sure: the names it has written whenever it ran to its end (its statements' own
            assignments, not those inside a branch or an operand).
    """

    reads: tuple[str, ...]
    writes: tuple[str, ...]
    sure: tuple[str, ...]


def _parts(expr: Expr) -> Iterator[Expr]:
    """``expr`` and every part inside it, in evaluation order (an assignment's value first)."""
    for f in fields(expr):
        value = getattr(expr, f.name)
        for item in value if isinstance(value, tuple) else (value,):
            if isinstance(item, Expr):
                yield from _parts(item)
    yield expr


def script_names(script: Script) -> ScriptNames:
    """The names ``script`` reads and writes (see :class:`ScriptNames`)."""
    reads: dict[str, None] = {}
    writes: dict[str, None] = {}
    sure: dict[str, None] = {}
    for statement in script.statements:
        for part in _parts(statement):
            if isinstance(part, Name) and part.name not in writes:
                reads[part.name] = None
            elif isinstance(part, Assign):
                if part.op != ":=" and part.name not in writes:  # = needs the entry too
                    reads[part.name] = None
                writes[part.name] = None
        chain: Expr = statement
        while isinstance(chain, Assign):
            sure[chain.name] = None
            chain = chain.value

    def plain(names: dict[str, None]) -> tuple[str, ...]:
        return tuple(n for n in names if not n.startswith("@"))

    return ScriptNames(plain(reads), plain(writes), plain(sure))


def parse_script(text: str) -> Script:
    """The script, parsed.

    Raises:
        ScriptSyntaxError: it is not in the language, or holds no statement; the error names
            the line and column.
    """
    statements = parse_statements(text, lambda offset: line_column(text, offset))
    if not statements:
        raise ScriptSyntaxError("expected a statement, got an empty script", 1, 1)
    return Script(text, tuple(statements))


def run_script(text: str, blackboard: Blackboard, enums: Mapping[str, int] | None = None) -> Any:
    """Parse and run a script on a blackboard (its top scope); the value of its last statement.

    Raises:
        ScriptError: a parse error or a run's failure.
    """
    return parse_script(text).run(ScriptEnv(blackboard, enums))
