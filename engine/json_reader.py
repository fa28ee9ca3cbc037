"""The one reader of user JSON files: plans, scenes, object models, cells, libraries.

Loading (:func:`read_json_file`, :func:`parse_json`) refuses, with the file and where:
text that is not UTF-8, text that is not JSON (line and column), a key given twice in one
object, NaN and Infinity, integers longer than :data:`MAX_DIGITS` digits and nesting deeper
than a limit (the JSON path and the line of the first value too deep). :class:`JsonReader`
then gives typed access to the parsed document; every error is a :class:`JsonFileError`
naming the file as the user gave it, the JSON path (``$.tree.children[2].params.speed``)
and what was expected::

    doc = JsonReader(read_json_file(path, "scene"), path)
    doc.fields(("format_version", "name", "table"), required=("format_version",))
    name = doc.text("name")
    size = doc.vector3("size", default=(0.8, 1.2, 0.75))
    for marker in doc.items("markers"):
        marker_id = marker.integer("id", lo=0, hi=49)

Nothing in a file is executed.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from engine.errors import EngineError
from engine.types import ParamType, Pose, ValueShapeError, decode_value

__all__ = [
    "MAX_DIGITS",
    "MAX_NESTING",
    "JsonFileError",
    "JsonReader",
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
    try:
        doc = json.loads(
            text,
            object_pairs_hook=_pairs,
            parse_constant=_constant,
            parse_int=_integer,
            parse_float=_float,
        )
    except json.JSONDecodeError as exc:
        cut = exc.pos >= len(text.rstrip())
        got = "the end of the file: it is cut off" if cut else f"a syntax error ({exc.msg})"
        raise error(file, "", "valid JSON", got, exc.lineno, exc.colno) from exc
    except RecursionError as exc:
        path, line, column = _too_deep(text, max_depth)
        expected = f"nesting at most {max_depth} levels deep"
        raise error(file, path, expected, "deeper nesting", line, column) from exc
    problem = _walk_problem(doc, max_depth)
    if problem is not None:
        raise error(file, *problem)
    return doc


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


# --------------------------------------------------------------------------- typed access


class JsonReader:
    """Typed access to one value of a parsed document; errors name file, JSON path, expectation.

    Accessors taking a ``key`` read a field of this value (which must be an object): a
    ``default`` of None means the field is required. The ``as_*`` methods check this value
    itself.

    Args:
        value: the parsed value.
        file: the file as the user gave it.
        path: the JSON path of ``value``.
        error: the JsonFileError class to raise.
    """

    __slots__ = ("error", "file", "path", "value")

    def __init__(
        self,
        value: Any,
        file: str | os.PathLike[str],
        path: str = "$",
        error: ErrorClass = JsonFileError,
    ) -> None:
        self.value = value
        self.file = os.fspath(file)
        self.path = path
        self.error = error

    def fail(self, expected: str, got: str | None = None, key: str | int | None = None) -> NoReturn:
        """Raise the error for this value (or its field ``key``)."""
        path = self.path if key is None else at(self.path, key)
        if got is None:
            got = describe(self.value if key is None else self._field(key))
        raise self.error(self.file, path, expected, got)

    def _field(self, key: str | int) -> Any:
        if isinstance(self.value, dict) and isinstance(key, str):
            return self.value.get(key)
        if isinstance(self.value, list) and isinstance(key, int) and key < len(self.value):
            return self.value[key]
        return None

    # ---- this value

    def as_object(
        self, fields: Sequence[str] | None = None, required: Sequence[str] = ()
    ) -> dict[str, Any]:
        """This value as an object; with ``fields``, no other field is allowed."""
        if not isinstance(self.value, dict):
            names = ", ".join(required or fields or ())
            self.fail(f"an object with {names}" if names else "an object")
        if fields is not None:
            for key in self.value:
                if key not in fields:
                    self.fail(f"one of the fields {', '.join(fields)}", f"{key!r}", key)
        for key in required:
            if key not in self.value:
                self.fail("a value here (it is required)", "nothing", key)
        return self.value

    def as_list(self, what: str = "values") -> list[Any]:
        """This value as a list."""
        if not isinstance(self.value, list):
            self.fail(f"a list of {what}")
        return self.value

    def as_text(self, nonempty: bool = False) -> str:
        """This value as a text (not blank with ``nonempty``)."""
        if not isinstance(self.value, str) or (nonempty and not self.value.strip()):
            self.fail("a non-empty text" if nonempty else "a text")
        return self.value

    def as_number(self, lo: float = -math.inf, hi: float = math.inf, above: bool = False) -> float:
        """This value as a float in [lo, hi] (in (lo, hi] with ``above``)."""
        value = self.value
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not number or not (lo < value if above else lo <= value) or not value <= hi:
            self.fail(_range_text("a number", lo, hi, above))
        return float(value)

    def as_integer(self, lo: int | None = None, hi: int | None = None) -> int:
        """This value as a whole number (a JSON integer) in [lo, hi]."""
        value = self.value
        low = -math.inf if lo is None else lo
        high = math.inf if hi is None else hi
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            self.fail(_range_text("a whole number", low, high, False))
        return value

    def as_bool(self) -> bool:
        """This value as true or false."""
        if not isinstance(self.value, bool):
            self.fail("true or false")
        return self.value

    def as_choice(self, choices: Sequence[str]) -> str:
        """This value as one of ``choices``."""
        if not isinstance(self.value, str) or self.value not in choices:
            self.fail(f"one of {', '.join(choices)}")
        return self.value

    def as_vector(self, n: int) -> tuple[float, ...]:
        """This value as a list of ``n`` numbers."""
        value = self.value
        if not isinstance(value, list) or len(value) != n or not all(_finite(v) for v in value):
            self.fail(f"a list of {n} finite numbers")
        return tuple(float(v) for v in value)

    def as_typed(self, ptype: ParamType) -> Any:
        """This value decoded as a parameter type (:func:`engine.types.decode_value`)."""
        try:
            return decode_value(ptype, self.value, self.path)
        except ValueShapeError as exc:
            raise self.error(self.file, exc.path, exc.expected, exc.got_text) from exc

    # ---- fields of this object

    def has(self, key: str) -> bool:
        """True when this value is an object with the field ``key``."""
        return isinstance(self.value, dict) and key in self.value

    def keys(self) -> list[str]:
        """The fields of this object, in file order."""
        return list(self.as_object())

    def at(self, key: str | int) -> JsonReader:
        """A reader of the field ``key`` (or list item ``key``); it must be there."""
        if isinstance(key, int):
            items = self.as_list()
            if not 0 <= key < len(items):
                self.fail(f"a list of at least {key + 1} items")
            return JsonReader(items[key], self.file, at(self.path, key), self.error)
        obj = self.as_object()
        if key not in obj:
            self.fail("a value here (it is required)", "nothing", key)
        return JsonReader(obj[key], self.file, at(self.path, key), self.error)

    def get(self, key: str, default: Any = None) -> Any:
        """The raw value of the field ``key``, or ``default`` when absent."""
        return self.as_object().get(key, default)

    def child(
        self,
        key: str,
        fields: Sequence[str] | None = None,
        required: Sequence[str] = (),
        optional: bool = True,
    ) -> JsonReader:
        """A reader of the object in field ``key`` (an empty object when absent and ``optional``)."""
        if not self.has(key):
            if not optional:
                self.fail("an object here (it is required)", "nothing", key)
            self.as_object()
            return JsonReader({}, self.file, at(self.path, key), self.error)
        reader = self.at(key)
        reader.as_object(fields, required)
        return reader

    def items(self, key: str, what: str = "values", optional: bool = True) -> list[JsonReader]:
        """Readers of the items of the list in field ``key`` (none when absent and ``optional``)."""
        if not self.has(key):
            if not optional:
                self.fail(f"a list of {what} here (it is required)", "nothing", key)
            self.as_object()
            return []
        reader = self.at(key)
        here = reader.path
        return [
            JsonReader(v, self.file, at(here, i), self.error)
            for i, v in enumerate(reader.as_list(what))
        ]

    def entries(self, key: str, what: str = "values") -> list[tuple[str, JsonReader]]:
        """(name, reader) of each field of the object in field ``key`` (none when absent)."""
        if not self.has(key):
            self.as_object()
            return []
        reader = self.at(key)
        obj = reader.value
        if not isinstance(obj, dict):
            reader.fail(f"an object of {what} by name")
        return [
            (k, JsonReader(v, self.file, at(reader.path, k), self.error)) for k, v in obj.items()
        ]

    def text(self, key: str, default: str | None = None, nonempty: bool = False) -> str:
        """The text in field ``key``."""
        return (
            default if default is not None and not self.has(key) else self.at(key).as_text(nonempty)
        )

    def number(
        self,
        key: str,
        default: float | None = None,
        lo: float = -math.inf,
        hi: float = math.inf,
        above: bool = False,
    ) -> float:
        """The number in field ``key``, in [lo, hi] (in (lo, hi] with ``above``)."""
        if default is not None and not self.has(key):
            return default
        return self.at(key).as_number(lo, hi, above)

    def integer(
        self, key: str, default: int | None = None, lo: int | None = None, hi: int | None = None
    ) -> int:
        """The whole number in field ``key``, in [lo, hi]."""
        return (
            default
            if default is not None and not self.has(key)
            else self.at(key).as_integer(lo, hi)
        )

    def flag(self, key: str, default: bool | None = None) -> bool:
        """The true or false in field ``key``."""
        return default if default is not None and not self.has(key) else self.at(key).as_bool()

    def choice(self, key: str, choices: Sequence[str], default: str | None = None) -> str:
        """The text in field ``key``, one of ``choices``."""
        return (
            default
            if default is not None and not self.has(key)
            else self.at(key).as_choice(choices)
        )

    def vector(self, key: str, n: int, default: Sequence[float] | None = None) -> tuple[float, ...]:
        """The list of ``n`` numbers in field ``key``."""
        if default is not None and not self.has(key):
            return tuple(float(v) for v in default)
        return self.at(key).as_vector(n)

    def vector2(self, key: str, default: Sequence[float] | None = None) -> tuple[float, float]:
        """The list of 2 numbers in field ``key``."""
        x, y = self.vector(key, 2, default)
        return (x, y)

    def vector3(
        self, key: str, default: Sequence[float] | None = None
    ) -> tuple[float, float, float]:
        """The list of 3 numbers in field ``key``."""
        x, y, z = self.vector(key, 3, default)
        return (x, y, z)

    def vector4(
        self, key: str, default: Sequence[float] | None = None
    ) -> tuple[float, float, float, float]:
        """The list of 4 numbers in field ``key``."""
        x, y, z, w = self.vector(key, 4, default)
        return (x, y, z, w)

    def typed(self, key: str, ptype: ParamType, default: Any = None) -> Any:
        """The value in field ``key`` decoded as a parameter type."""
        return (
            default if default is not None and not self.has(key) else self.at(key).as_typed(ptype)
        )

    def pose(self, key: str, default: Pose | None = None) -> Pose:
        """The pose (``{"position", "orientation"}``) in field ``key``."""
        if default is not None and not self.has(key):
            return default
        pose = self.at(key).as_typed(ParamType.POSE)
        assert isinstance(pose, Pose)  # decode_value(POSE) returns a Pose
        return pose

    def check_version(self, versions: Sequence[int], key: str = "format_version") -> int:
        """The file's format version, one of ``versions``; a newer one says so."""
        value = self.get(key)
        readable = ", ".join(str(v) for v in versions)
        if isinstance(value, int) and not isinstance(value, bool) and value > max(versions):
            self.fail(
                f"a {key} this program reads ({readable}); the file was written by a newer version",
                f"{key} {value}",
                key,
            )
        if isinstance(value, bool) or value not in versions:
            self.fail(f"one of the format versions {readable}", describe(value), key)
        return int(value)


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _range_text(what: str, lo: float, hi: float, above: bool) -> str:
    low, high = math.isfinite(lo), math.isfinite(hi)
    if low and high:
        return f"{what} from {lo:g} to {hi:g}" + (f" (above {lo:g})" if above else "")
    if low:
        return f"{what} above {lo:g}" if above else f"{what} of {lo:g} or more"
    if high:
        return f"{what} of {hi:g} or less"
    return what
