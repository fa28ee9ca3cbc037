"""The one reader of user JSON files: plans, scenes, object models, cells, libraries.

Loading (:func:`read_json_file`, :func:`parse_json`, from :mod:`engine.json_text`) refuses,
with the file and where: text that is not UTF-8, text that is not JSON (line and column), a
key given twice in one object, NaN and Infinity, over-long integers and nesting deeper than a
limit. :class:`JsonReader` then gives typed access to the parsed document; every error is a
:class:`JsonFileError` naming the file as the user gave it, the JSON path
(``$.tree.children[2].params.speed``) and what was expected::

    doc = JsonReader(read_json_file(path, "scene"), path)
    doc.as_object(("format_version", "name", "table"), required=("format_version",))
    name = doc.text("name")
    size = doc.vector3("size", default=(0.8, 1.2, 0.75))
    for marker in doc.items("markers", "markers"):
        marker_id = marker.integer("id", lo=0, hi=49)

Capability-side readers wrap a JsonFileError into their own CapabilityError subclass
(``with errors_as(SceneFileError): ...``, :func:`errors_as`); the engine raises it (or a subclass such as
PlanFileError, chosen with ``error=``) as is. Nothing in a file is executed.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, NoReturn

from engine.json_text import (
    MAX_DIGITS,
    MAX_NESTING,
    ErrorClass,
    JsonFileError,
    at,
    describe,
    parse_json,
    read_json_file,
)
from engine.types import ParamType, Pose, ValueShapeError, decode_value

__all__ = [
    "MAX_DIGITS",
    "MAX_NESTING",
    "ErrorClass",
    "JsonFileError",
    "JsonReader",
    "at",
    "describe",
    "errors_as",
    "parse_json",
    "read_json_file",
]


@contextmanager
def errors_as(error: Callable[[str], Exception]) -> Iterator[None]:
    """A JsonFileError raised in the block is raised again as ``error`` (a reader's own error
    class) with the same message, the JsonFileError its ``__cause__``.
    """
    try:
        yield
    except JsonFileError as exc:
        raise error(str(exc)) from exc


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
