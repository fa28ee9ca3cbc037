"""The object model library: what the cell and perception know about each kind of object.

A model is a folder ``<library>/<name>/`` with ``model.json`` (format_version 1) and a mesh
(OBJ, metres, object frame at the bottom centre, z up). ``model.json`` fields:

- ``name`` (the folder's name), ``description``, ``mesh`` (file name in the folder)
- ``collision``: ``{"type": "cylinder", "radius", "height"}``, ``{"type": "box", "size",
  "position"?}``, ``{"type": "compound", "boxes": [{"size", "position"}]}`` or
  ``{"type": "convex_hull"}`` (of the mesh); all standing on z=0 of the object frame
- ``mass`` (kg), ``center_of_mass`` (m, object frame, optional), ``dimensions`` (bounding box, m)
- ``symmetry``: ``{"kind": "none"}``, ``{"kind": "continuous", "axis"}`` or
  ``{"kind": "discrete", "axis", "order"}`` (rotations by 2*pi/order about the axis)
- ``markers``: ``[{"id", "size", "pose": {"position", "orientation"}}]``: ArUco DICT_4X4_50
  ids, side in m (black border included), marker frame in the object frame (see
  markers_texture for the convention)
- ``color`` (RGBA 0..1), ``friction`` (optional, default 0.6); other fields are kept in ``extra``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.types import ParamType, Pose, ValueError_, decode_value

__all__ = [
    "BoxPart",
    "CollisionSpec",
    "MarkerSpec",
    "ObjectLibrary",
    "ObjectLibraryError",
    "ObjectModelSpec",
    "Symmetry",
    "default_library_path",
    "parse_model",
]

FORMAT_VERSION = 1
_KNOWN_FIELDS = {
    "format_version", "name", "description", "mesh", "collision", "mass", "center_of_mass",
    "dimensions", "symmetry", "markers", "color", "friction",
}  # fmt: skip


class ObjectLibraryError(Exception):
    """A model folder or its model.json is missing or malformed; the message names the field."""


def default_library_path() -> Path:
    """``resources/objects`` of this checkout."""
    return Path(__file__).resolve().parents[1] / "resources" / "objects"


@dataclass(frozen=True)
class MarkerSpec:
    """An ArUco marker on an object: id, side (m, border included), pose in the object frame."""

    marker_id: int
    size: float
    pose: Pose


@dataclass(frozen=True)
class BoxPart:
    """One box of a collision description: full size and centre in the object frame (m)."""

    size: tuple[float, float, float]
    position: tuple[float, float, float]


@dataclass(frozen=True)
class CollisionSpec:
    """How an object collides: ``kind`` is cylinder, box, compound or convex_hull."""

    kind: str
    radius: float = 0.0
    height: float = 0.0
    boxes: tuple[BoxPart, ...] = ()


@dataclass(frozen=True)
class Symmetry:
    """Rotations about ``axis`` (object frame) that map the object's shape onto itself.

    ``kind`` is ``none``, ``continuous`` or ``discrete`` (``order`` rotations of 2*pi/order).
    """

    kind: str = "none"
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    order: int = 1

    def angles(self) -> tuple[float, ...] | None:
        """The equivalent rotation angles (rad), or None when every angle is (continuous)."""
        if self.kind == "continuous":
            return None
        return tuple(2 * math.pi * k / self.order for k in range(self.order))


@dataclass(frozen=True)
class ObjectModelSpec:
    """A parsed ``model.json``: everything the cell and perception know about a model."""

    name: str
    directory: Path
    mesh_file: Path
    collision: CollisionSpec
    mass: float
    center_of_mass: tuple[float, float, float]
    dimensions: tuple[float, float, float]
    symmetry: Symmetry
    markers: tuple[MarkerSpec, ...]
    color: tuple[float, float, float, float]
    friction: float = 0.6
    description: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def footprint_radius(self) -> float:
        """Radius (m) of the circle around the bottom centre that covers the footprint."""
        return math.hypot(self.dimensions[0], self.dimensions[1]) / 2


class _Fields:
    """Typed access to a JSON object that names the file and JSON path in every error."""

    def __init__(self, data: Any, file: Path, path: str) -> None:
        self.file, self.path = file, path
        if not isinstance(data, dict):
            self.fail(path, "an object", data)
        self.data: dict[str, Any] = data

    def fail(self, path: str, expected: str, got: Any) -> None:
        err = ValueError_(path, expected, got)
        raise ObjectLibraryError(f"{self.file}: {err}")

    def get(self, key: str, default: Any = ...) -> Any:
        if key not in self.data:
            if default is ...:
                self.fail(f"{self.path}.{key}", "a value (missing)", None)
            return default
        return self.data[key]

    def number(self, key: str, default: Any = ..., minimum: float = 0.0) -> float:
        value = self.get(key, default)
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not ok or not math.isfinite(value) or value <= minimum:
            self.fail(f"{self.path}.{key}", f"a number above {minimum}", value)
        return float(value)

    def vector(self, key: str, n: int, default: Any = ...) -> tuple[float, ...]:
        value = self.get(key, default)
        try:
            return _floats(value, n)
        except (TypeError, ValueError):
            self.fail(f"{self.path}.{key}", f"a list of {n} numbers", value)
        raise AssertionError  # unreachable: fail() raises

    def text(self, key: str, default: Any = ...) -> str:
        value = self.get(key, default)
        if not isinstance(value, str):
            self.fail(f"{self.path}.{key}", "a text string", value)
        return str(value)

    def pose(self, key: str) -> Pose:
        try:
            return decode_value(ParamType.POSE, self.get(key), f"{self.path}.{key}")  # type: ignore[no-any-return]
        except ValueError_ as exc:
            raise ObjectLibraryError(f"{self.file}: {exc}") from exc

    def child(self, key: str) -> _Fields:
        return _Fields(self.get(key), self.file, f"{self.path}.{key}")


def _floats(value: Any, n: int) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise ValueError("length")
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise TypeError("not numbers")
    if not all(math.isfinite(v) for v in value):
        raise ValueError("not finite")
    return tuple(float(v) for v in value)


def _parse_collision(f: _Fields) -> CollisionSpec:
    kind = f.text("type")
    if kind == "cylinder":
        return CollisionSpec(kind, radius=f.number("radius"), height=f.number("height"))
    if kind == "box":
        size = f.vector("size", 3)
        pos = f.vector("position", 3, [0.0, 0.0, size[2] / 2])
        return CollisionSpec(kind, boxes=(BoxPart(size, pos),))  # type: ignore[arg-type]
    if kind == "compound":
        boxes = f.get("boxes")
        if not isinstance(boxes, list) or not boxes:
            f.fail(f"{f.path}.boxes", "a non-empty list of boxes", boxes)
        parts = []
        for i, item in enumerate(boxes):
            b = _Fields(item, f.file, f"{f.path}.boxes[{i}]")
            parts.append(BoxPart(b.vector("size", 3), b.vector("position", 3)))  # type: ignore[arg-type]
        return CollisionSpec(kind, boxes=tuple(parts))
    if kind == "convex_hull":
        return CollisionSpec(kind)
    f.fail(f"{f.path}.type", "one of cylinder, box, compound, convex_hull", kind)
    raise AssertionError


def _parse_symmetry(f: _Fields) -> Symmetry:
    kind = f.text("kind")
    if kind == "none":
        return Symmetry()
    axis = f.vector("axis", 3)
    if kind == "continuous":
        return Symmetry(kind, axis)  # type: ignore[arg-type]
    if kind == "discrete":
        order = f.get("order")
        if not isinstance(order, int) or isinstance(order, bool) or order < 1:
            f.fail(f"{f.path}.order", "a whole number of 1 or more", order)
        return Symmetry(kind, axis, order)  # type: ignore[arg-type]
    f.fail(f"{f.path}.kind", "one of none, continuous, discrete", kind)
    raise AssertionError


def _parse_markers(f: _Fields) -> tuple[MarkerSpec, ...]:
    items = f.get("markers", [])
    if not isinstance(items, list):
        f.fail(f"{f.path}.markers", "a list of markers", items)
    out = []
    for i, item in enumerate(items):
        m = _Fields(item, f.file, f"{f.path}.markers[{i}]")
        marker_id = m.get("id")
        if not isinstance(marker_id, int) or isinstance(marker_id, bool) or not 0 <= marker_id < 50:
            m.fail(f"{m.path}.id", "a DICT_4X4_50 marker id (0..49)", marker_id)
        out.append(MarkerSpec(marker_id, m.number("size"), m.pose("pose")))
    return tuple(out)


def parse_model(data: Any, directory: Path, file: Path) -> ObjectModelSpec:
    """Check and convert the content of a ``model.json``; raise ObjectLibraryError."""
    f = _Fields(data, file, "$")
    version = f.get("format_version")
    if version != FORMAT_VERSION:
        f.fail("$.format_version", f"{FORMAT_VERSION}", version)
    name = f.text("name")
    if name != directory.name:
        f.fail("$.name", f"the folder's name {directory.name!r}", name)
    mesh_file = directory / f.text("mesh")
    if not mesh_file.is_file():
        f.fail("$.mesh", f"a file in {directory}", str(mesh_file.name))
    dimensions = f.vector("dimensions", 3)
    if min(dimensions) <= 0:
        f.fail("$.dimensions", "three sizes above 0 m", list(dimensions))
    return ObjectModelSpec(
        name=name,
        directory=directory,
        mesh_file=mesh_file,
        collision=_parse_collision(f.child("collision")),
        mass=f.number("mass"),
        center_of_mass=f.vector("center_of_mass", 3, [0.0, 0.0, dimensions[2] / 2]),  # type: ignore[arg-type]
        dimensions=dimensions,  # type: ignore[arg-type]
        symmetry=_parse_symmetry(f.child("symmetry")) if "symmetry" in f.data else Symmetry(),
        markers=_parse_markers(f),
        color=f.vector("color", 4, [0.7, 0.7, 0.7, 1.0]),  # type: ignore[arg-type]
        friction=f.number("friction", 0.6),
        description=f.text("description", ""),
        extra={k: v for k, v in f.data.items() if k not in _KNOWN_FIELDS},
    )


class ObjectLibrary:
    """The models in a folder (one sub-folder per model); add a model by adding a folder.

    Args:
        path: the library folder (default: ``resources/objects``).
    """

    def __init__(self, path: Path | str | None = None) -> None:
        self._path = Path(path) if path is not None else default_library_path()
        self._models: dict[str, ObjectModelSpec] = {}

    @property
    def path(self) -> Path:
        """The library folder."""
        return self._path

    def names(self) -> list[str]:
        """Names of the models in the folder, sorted."""
        return sorted(d.name for d in self._path.iterdir() if (d / "model.json").is_file())

    def get(self, name: str) -> ObjectModelSpec:
        """The model called ``name``; raise ObjectLibraryError naming the file and field."""
        if name not in self._models:
            directory = self._path / name
            file = directory / "model.json"
            if not file.is_file():
                raise ObjectLibraryError(
                    f"{file}: no such model {name!r} (library {self._path} has {self.names()})"
                )
            try:
                data = json.loads(file.read_text(encoding="utf-8"))
            except json.JSONDecodeError as exc:
                raise ObjectLibraryError(f"{file}: line {exc.lineno}: not JSON: {exc.msg}") from exc
            self._models[name] = parse_model(data, directory, file)
        return self._models[name]
