"""Loading user JSON files with clear errors: the first half of :mod:`engine.json_reader`.

:func:`parse_json` and :func:`read_json_file` refuse, naming the file as the user gave it:
text that is not UTF-8, text that is not JSON (line and column), a key given twice in one
object, NaN and Infinity, integers longer than :data:`MAX_DIGITS` digits and nesting deeper
than a limit (the JSON path and the line of the first value too deep). Import these names
from :mod:`engine.json_reader`, which re-exports them with the typed reader.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

from engine.errors import EngineError

__all__ = [
    "MAX_DIGITS",
    "MAX_NESTING",
    "ErrorClass",
    "JsonFileError",
    "at",
    "describe",
    "parse_json",
    "read_json_file",
]

MAX_NESTING = 100
"""Default limit of nested objects and lists (the document itself is level 1)."""
MAX_DIGITS = 100
"""Longest integer accepted, in digits (Python refuses more than 4300 without saying where)."""

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{},:]', re.DOTALL)


class JsonFileError(EngineError):
    """A user file that cannot be read, with where and what was expected.

    Attributes:
        file: the file as the user gave it (``"<string>"`` for text not from a file).
        json_path: where in the document (``$.tree.children[1].params.target``); empty when
            the problem is the file as a whole.
        expected: what should have been there.
        got: what was there.
        line: line of the problem (1-based) when known, else None.
        column: column of the problem (1-based) when known, else None.
    """

    def __init__(
        self,
        file: str,
        json_path: str,
        expected: str,
        got: str,
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        self.file = file
        self.json_path = json_path
        self.expected = expected
        self.got = got
        self.line = line
        self.column = column
        where = [file]
        if line is not None:
            where.append(f"line {line} column {column}")
        if json_path:
            where.append(_short(json_path))
        super().__init__(f"{': '.join(where)}: expected {expected}, got {got}")


def _short(path: str) -> str:
    """A JSON path short enough for a message (a path 800 levels deep is not read by anyone)."""
    if len(path) <= 200:
        return path
    return f"{path[:120]}...{path[-60:]}"


ErrorClass = Callable[..., JsonFileError]
"""A JsonFileError class (or subclass) the reader raises; same arguments as JsonFileError."""


def describe(value: Any) -> str:
    """A short plain description of a JSON value for error messages."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, str):
        text = value if len(value) <= 40 else value[:37] + "..."
        return f"the text {text!r}"
    if isinstance(value, list):
        return f"a list of {len(value)} item{'' if len(value) == 1 else 's'}"
    if isinstance(value, dict):
        keys = ", ".join(list(value)[:6]) + (", ..." if len(value) > 6 else "")
        return f"an object with {keys}" if value else "an empty object"
    return type(value).__name__


def at(path: str, key: str | int) -> str:
    """The JSON path of ``key`` inside ``path``: ``$.tree``, ``$.tree.children[0]``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if _IDENT.match(key) else f"{path}[{json.dumps(key)}]"


# --------------------------------------------------------------------------- loading


class _Twice(dict[str, Any]):
    """A parsed object that had a key more than once (JSON keeps the last)."""

    def __init__(self, pairs: list[tuple[str, Any]]) -> None:
        super().__init__(pairs)
        seen: set[str] = set()
        self.twice = ""
        for key, _ in pairs:
            if key in seen:
                self.twice = key
                break
            seen.add(key)


class _BadNumber:
    """Stands in for NaN, Infinity or an over-long integer until the walk names its path."""

    def __init__(self, text: str, expected: str) -> None:
        self.text, self.expected = text, expected


def _pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    obj = dict(pairs)
    return obj if len(obj) == len(pairs) else _Twice(pairs)


def _constant(name: str) -> _BadNumber:
    return _BadNumber(name, "a finite number (JSON has no NaN or Infinity)")


def _integer(text: str) -> int | _BadNumber:
    if len(text.lstrip("-")) > MAX_DIGITS:
        return _BadNumber(f"an integer of {len(text.lstrip('-'))} digits", "a shorter number")
    return int(text)


def _float(text: str) -> float | _BadNumber:
    value = float(text)
    if math.isfinite(value):
        return value
    return _BadNumber(f"{text[:20]}... (too large)", "a number a float can hold")


def _walk_problem(doc: Any, max_depth: int) -> tuple[str, str, str] | None:
    """(path, expected, got) of the first thing off in document order, or None."""
    stack: list[tuple[str, Any, int]] = [("$", doc, 1)]
    while stack:
        path, value, depth = stack.pop()
        if isinstance(value, (dict, list)) and depth > max_depth:
            return path, f"nesting at most {max_depth} levels deep", "deeper nesting"
        if isinstance(value, _Twice):
            return path, "each field at most once in an object", f"{value.twice!r} twice"
        if isinstance(value, _BadNumber):
            return path, value.expected, value.text
        if isinstance(value, dict):
            stack.extend((at(path, k), v, depth + 1) for k, v in reversed(value.items()))
        elif isinstance(value, list):
            stack.extend((at(path, i), v, depth + 1) for i, v in reversed(list(enumerate(value))))
    return None


def _too_deep(text: str, max_depth: int) -> tuple[str, int, int]:
    """(JSON path, line, column) of the first bracket deeper than ``max_depth``."""
    frames: list[list[Any]] = []  # [path, key or index, is object, key pending]
    path = "$"
    last_string = ""
    for match in _TOKEN.finditer(text):
        token = match.group()
        if token in "[{":
            if frames:
                top = frames[-1]
                path = at(top[0], top[1])
            if len(frames) + 1 > max_depth:
                line = text.count("\n", 0, match.start()) + 1
                column = match.start() - text.rfind("\n", 0, match.start())
                return path, line, column
            frames.append([path, 0 if token == "[" else "", token == "{"])
        elif token in "]}":
            frames.pop()
            path = frames[-1][0] if frames else "$"
        elif token == ",":
            if frames and not frames[-1][2]:
                frames[-1][1] += 1
        elif token == ":":
            if frames:
                frames[-1][1] = last_string
        else:
            last_string = json.loads(token)
    return "$", 1, 1  # not reached for text that was too deep to parse


def parse_json(
    text: str | bytes,
    file: str = "<string>",
    what: str = "JSON",
    *,
    max_depth: int = MAX_NESTING,
    error: ErrorClass = JsonFileError,
) -> Any:
    """Parse the text of a user file, refusing what JSON or this program does not allow.

    Args:
        text: the file's text, or its bytes (UTF-8, a byte-order mark is skipped).
        file: the file as the user gave it, for messages.
        what: what the file should be (``"plan"``, ``"scene"``), for messages.
        max_depth: the deepest nesting of objects and lists allowed.
        error: the JsonFileError class to raise.

    Returns:
        The parsed document (dicts, lists, str, int, float, bool, None).

    Raises:
        JsonFileError: not UTF-8, not JSON, a key twice, NaN, Infinity, an over-long
            number or nesting deeper than ``max_depth``.
    """
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            got = f"a byte that is not UTF-8 at offset {exc.start}"
            raise error(file, "", f"UTF-8 text (the file is not a {what} file)", got) from exc
    hooks = _Hooks()
    try:
        doc = json.loads(
            text,
            object_pairs_hook=hooks.pairs,
            parse_constant=hooks.constant,
            parse_int=hooks.integer,
            parse_float=hooks.real,
        )
    except json.JSONDecodeError as exc:
        cut = exc.pos >= len(text.rstrip())
        got = "the end of the file: it is cut off" if cut else f"a syntax error ({exc.msg})"
        raise error(file, "", "valid JSON", got, exc.lineno, exc.colno) from exc
    except RecursionError as exc:
        path, line, column = _too_deep(text, max_depth)
        expected = f"nesting at most {max_depth} levels deep"
        raise error(file, path, expected, "deeper nesting", line, column) from exc
    # The walk finds where a problem is; most texts have none to find (a run record's
    # lines: the walk was 60% of reading one).
    if hooks.flagged or text.count("[") + text.count("{") > max_depth:
        problem = _walk_problem(doc, max_depth)
        if problem is not None:
            raise error(file, *problem)
    return doc


class _Hooks:
    """The parser's hooks for one text; ``flagged`` once one of them marked a problem."""

    def __init__(self) -> None:
        self.flagged = False

    def pairs(self, pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        obj = _pairs(pairs)
        self.flagged = self.flagged or isinstance(obj, _Twice)
        return obj

    def constant(self, name: str) -> _BadNumber:
        self.flagged = True
        return _constant(name)

    def integer(self, text: str) -> int | _BadNumber:
        value = _integer(text)
        self.flagged = self.flagged or isinstance(value, _BadNumber)
        return value

    def real(self, text: str) -> float | _BadNumber:
        value = _float(text)
        self.flagged = self.flagged or isinstance(value, _BadNumber)
        return value


def read_json_file(
    path: str | os.PathLike[str],
    what: str = "JSON",
    *,
    max_depth: int = MAX_NESTING,
    error: ErrorClass = JsonFileError,
) -> Any:
    """Read and parse a user file; errors name the file as given (see :func:`parse_json`).

    Raises:
        JsonFileError: the file is missing or unreadable, or :func:`parse_json` refuses it.
    """
    file = os.fspath(path)
    try:
        data = Path(file).read_bytes()
    except FileNotFoundError as exc:
        raise error(file, "", f"a {what} file", f"no file at {file}") from exc
    except OSError as exc:
        raise error(file, "", f"a readable {what} file", exc.strerror or str(exc)) from exc
    return parse_json(data, file, what, max_depth=max_depth, error=error)
