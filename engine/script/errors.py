"""The errors of BehaviorTree.CPP scripts: one base, a parse error and the errors of a run.

Every error names where in the script it is (line and column, both from 1) and what was
expected there, so that an imported file's problem can be found in its ``code`` attribute.
"""

from __future__ import annotations

from engine.errors import EngineError

__all__ = [
    "ScriptError",
    "ScriptSyntaxError",
    "ScriptRunError",
    "ScriptNameError",
    "ScriptTypeError",
    "line_column",
]


def line_column(text: str, offset: int) -> tuple[int, int]:
    """The line and column (both from 1) of the character at ``offset`` in ``text``."""
    before = text[:offset]
    line = before.count("\n") + 1
    return line, offset - (before.rfind("\n") + 1) + 1


class ScriptError(EngineError):
    """A script that cannot be parsed or that fails while it runs.

    Attributes:
        reason: what went wrong, without the place.
        line: the line of the script (from 1).
        column: the column in that line (from 1).
    """

    def __init__(self, reason: str, line: int, column: int) -> None:
        self.reason = reason
        self.line = line
        self.column = column
        super().__init__(f"line {line}, column {column}: {reason}")


class ScriptSyntaxError(ScriptError):
    """The script is not in BehaviorTree.CPP's scripting language (found when it is parsed)."""


class ScriptRunError(ScriptError):
    """The script parsed but failed while it ran (an entry, a type, a division by zero)."""


class ScriptNameError(ScriptRunError):
    """A read of an entry that does not exist or has no value, or ``=`` to a missing entry."""


class ScriptTypeError(ScriptRunError):
    """An operator or an assignment got a value of a type it does not take."""
