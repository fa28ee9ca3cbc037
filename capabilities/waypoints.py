"""The waypoint library of a plan: a JSON file stored next to it.

A plan ``task.costar.json`` keeps its waypoints in ``task.waypoints.json``::

    {"format": "costar-waypoints", "format_version": 1,
     "waypoints": [{"name": "above_cup", "frame": "object", "reference": "cup",
                    "pose": {"position": [...], "orientation": [...]}}, ...]}

Waypoints are encoded with :func:`engine.types.encode_value` (SI units, quaternions x, y, z,
w). Saving is atomic (a temporary file renamed over the old one); reading checks everything
and names the file and the JSON path of what is wrong. Nothing in the file is executed.
"""

from __future__ import annotations

import dataclasses
import json
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from capabilities.errors import CapabilityError
from engine.types import ParamType, ValueError_, Waypoint, decode_value, encode_value

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "WaypointFileError",
    "WaypointLibrary",
    "waypoints_path_for",
]

FORMAT = "costar-waypoints"
FORMAT_VERSION = 1
_PLAN_SUFFIXES = (".costar.json", ".json")


class WaypointFileError(CapabilityError):
    """A waypoint file cannot be read or written, or an edit is not possible.

    Attributes:
        file: the file concerned (None for an edit of a library in memory).
        path: the JSON path of the problem ("$" for the whole file).
    """

    def __init__(self, message: str, file: Path | None = None, path: str = "$") -> None:
        self.file = file
        self.path = path
        where = f"{file}: {path}: " if file is not None else ""
        super().__init__(f"{where}{message}")


def waypoints_path_for(plan_path: Path | str) -> Path:
    """The waypoint file of a plan: ``task.costar.json`` -> ``task.waypoints.json``."""
    plan = Path(plan_path)
    name = plan.name
    for suffix in _PLAN_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            name = name[: -len(suffix)]
            break
    return plan.with_name(f"{name}.waypoints.json")


class WaypointLibrary:
    """Named waypoints in insertion order; names are unique.

    Args:
        waypoints: the starting waypoints.
    """

    def __init__(self, waypoints: Iterable[Waypoint] = ()) -> None:
        self._items: dict[str, Waypoint] = {}
        for waypoint in waypoints:
            self.add(waypoint)

    # ------------------------------------------------------------------ access

    def __len__(self) -> int:
        return len(self._items)

    def __iter__(self) -> Iterator[Waypoint]:
        return iter(list(self._items.values()))

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def names(self) -> list[str]:
        """The waypoints' names, in order."""
        return list(self._items)

    def get(self, name: str) -> Waypoint:
        """The waypoint called ``name``; raises WaypointFileError naming the known ones."""
        try:
            return self._items[name]
        except KeyError:
            raise WaypointFileError(f"no waypoint {name!r} (there are {self.names()})") from None

    # ------------------------------------------------------------------ edits

    def add(self, waypoint: Waypoint, replace: bool = False) -> None:
        """Add a waypoint; one of the same name is an error unless ``replace``."""
        if not waypoint.name.strip():
            raise WaypointFileError("a waypoint needs a name")
        if waypoint.name in self._items and not replace:
            raise WaypointFileError(f"there is already a waypoint {waypoint.name!r}")
        self._items[waypoint.name] = waypoint

    def remove(self, name: str) -> Waypoint:
        """Remove and return the waypoint called ``name``."""
        waypoint = self.get(name)
        del self._items[name]
        return waypoint

    def rename(self, old: str, new: str) -> Waypoint:
        """Give a waypoint a new name, keeping its place in the order."""
        waypoint = self.get(old)
        if not new.strip():
            raise WaypointFileError("a waypoint needs a name")
        if new != old and new in self._items:
            raise WaypointFileError(f"there is already a waypoint {new!r}")
        renamed = dataclasses.replace(waypoint, name=new)
        self._items = {
            (new if k == old else k): (renamed if k == old else v) for k, v in self._items.items()
        }
        return renamed

    # ------------------------------------------------------------------ files

    def to_json(self) -> dict[str, Any]:
        """The file's content as a JSON-ready mapping."""
        return {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "waypoints": [encode_value(w) for w in self._items.values()],
        }

    @classmethod
    def from_json(cls, data: Any, file: Path | None = None) -> WaypointLibrary:
        """Read the mapping of a file; raises WaypointFileError with the JSON path."""
        if not isinstance(data, dict):
            raise WaypointFileError("expected a JSON object", file)
        if data.get("format") != FORMAT:
            raise WaypointFileError(
                f"expected {FORMAT!r}, got {data.get('format')!r}", file, "$.format"
            )
        version = data.get("format_version")
        if version != FORMAT_VERSION:
            raise WaypointFileError(
                f"format_version {version!r} is not supported (this version reads {FORMAT_VERSION})",
                file,
                "$.format_version",
            )
        items = data.get("waypoints")
        if not isinstance(items, list):
            raise WaypointFileError("expected a list of waypoints", file, "$.waypoints")
        library = cls()
        for index, item in enumerate(items):
            path = f"$.waypoints[{index}]"
            try:
                waypoint = decode_value(ParamType.WAYPOINT, item, path)
            except ValueError_ as exc:
                raise WaypointFileError(f"expected {exc.expected}", file, exc.path) from exc
            if waypoint.name in library:
                raise WaypointFileError(
                    f"a second waypoint {waypoint.name!r}", file, f"{path}.name"
                )
            library.add(waypoint)
        return library

    @classmethod
    def load(cls, file: Path | str) -> WaypointLibrary:
        """Read a waypoint file."""
        file = Path(file)
        try:
            text = file.read_text(encoding="utf-8")
        except OSError as exc:
            raise WaypointFileError(f"cannot read: {exc.strerror or exc}", file) from exc
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise WaypointFileError(
                f"not JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})", file
            ) from exc
        return cls.from_json(data, file)

    def save(self, file: Path | str) -> None:
        """Write the file atomically: a temporary file in the same folder, then a rename."""
        file = Path(file)
        text = json.dumps(self.to_json(), indent=2, ensure_ascii=False) + "\n"
        try:
            handle, temp = tempfile.mkstemp(prefix=f".{file.name}.", suffix=".tmp", dir=file.parent)
        except OSError as exc:
            raise WaypointFileError(f"cannot write: {exc.strerror or exc}", file) from exc
        try:
            with os.fdopen(handle, "w", encoding="utf-8") as out:
                out.write(text)
                out.flush()
                os.fsync(out.fileno())
            os.replace(temp, file)
        except OSError as exc:
            Path(temp).unlink(missing_ok=True)
            raise WaypointFileError(f"cannot write: {exc.strerror or exc}", file) from exc
