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
- ``grasps`` (optional): ``[{"name", "tool", "pose", "approach"}]``, taught once relative to
  the object: ``pose`` is the tool's TCP in the object frame when it holds the object,
  ``approach`` the TCP pose it comes from and lifts back to; ``tool`` is ``gripper`` (the
  parallel gripper closes) or ``suction`` (the suction tool's cup takes it). The first grasp
  is the default; the symmetry gives each grasp its equivalents.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from capabilities.errors import CapabilityError
from engine.json_reader import JsonReader, errors_as, read_json_file
from engine.types import Pose
from resources import resource_path

__all__ = [
    "GRASP_TOOLS",
    "BoxPart",
    "CollisionSpec",
    "GraspSpec",
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
    "format_version",
    "name",
    "description",
    "mesh",
    "collision",
    "mass",
    "center_of_mass",
    "dimensions",
    "symmetry",
    "markers",
    "color",
    "friction",
    "grasps",
}
GRASP_TOOLS = ("gripper", "suction")
_MIN_APPROACH = 0.01  # m: an approach closer to the grasp than this is no approach


class ObjectLibraryError(CapabilityError):
    """A model folder or its model.json is missing or malformed; the message names the field.

    A malformed file wraps the reader's :class:`engine.json_reader.JsonFileError` (its
    ``__cause__``).
    """


def default_library_path() -> Path:
    """The shipped object library (``objects``)."""
    return resource_path("objects")


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
class GraspSpec:
    """A grasp taught once relative to the object (all poses in the object frame).

    Attributes:
        name: unique within the model ("top", "suction").
        tool: ``gripper`` or ``suction``: what takes the object.
        pose: the TCP pose that holds the object.
        approach: the TCP pose the tool comes from, straight to ``pose``, and lifts back to.
    """

    name: str
    tool: str
    pose: Pose
    approach: Pose


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
    grasps: tuple[GraspSpec, ...] = ()

    def grasp(self, name: str = "") -> GraspSpec:
        """The grasp called ``name`` (empty: the first); ObjectLibraryError names the choices."""
        if not self.grasps:
            raise ObjectLibraryError(f"{self.directory / 'model.json'}: {self.name} has no grasps")
        found = next((g for g in self.grasps if g.name == name), None) if name else self.grasps[0]
        if found is None:
            names = ", ".join(g.name for g in self.grasps)
            raise ObjectLibraryError(f"{self.name} has no grasp {name!r} (it has {names})")
        return found

    @property
    def footprint_radius(self) -> float:
        """Radius (m) of the circle around the bottom centre that covers the footprint."""
        return math.hypot(self.dimensions[0], self.dimensions[1]) / 2


def _parse_collision(f: JsonReader) -> CollisionSpec:
    kind = f.choice("type", ("cylinder", "box", "compound", "convex_hull"))
    if kind == "cylinder":
        radius, height = (
            f.number("radius", lo=0.0, above=True),
            f.number("height", lo=0.0, above=True),
        )
        return CollisionSpec(kind, radius=radius, height=height)
    if kind == "box":
        size = f.vector3("size")
        pos = f.vector3("position", (0.0, 0.0, size[2] / 2))
        return CollisionSpec(kind, boxes=(BoxPart(size, pos),))
    if kind == "compound":
        boxes = f.items("boxes", "boxes", optional=False)
        if not boxes:
            f.fail("a non-empty list of boxes", key="boxes")
        parts = tuple(BoxPart(b.vector3("size"), b.vector3("position")) for b in boxes)
        return CollisionSpec(kind, boxes=parts)
    return CollisionSpec(kind)


def _parse_symmetry(f: JsonReader) -> Symmetry:
    kind = f.choice("kind", ("none", "continuous", "discrete"))
    if kind == "none":
        return Symmetry()
    axis = f.vector3("axis")
    if kind == "continuous":
        return Symmetry(kind, axis)
    return Symmetry(kind, axis, f.integer("order", lo=1))


def _parse_markers(f: JsonReader) -> tuple[MarkerSpec, ...]:
    return tuple(
        MarkerSpec(
            m.integer("id", lo=0, hi=49), m.number("size", lo=0.0, above=True), m.pose("pose")
        )
        for m in f.items("markers", "markers")
    )


def _parse_grasps(f: JsonReader) -> tuple[GraspSpec, ...]:
    grasps: list[GraspSpec] = []
    for g in f.items("grasps", "grasps"):
        name = g.text("name", nonempty=True)
        if name in (known.name for known in grasps):
            g.fail("a grasp name not used before in this model", key="name")
        grasp = GraspSpec(name, g.choice("tool", GRASP_TOOLS), g.pose("pose"), g.pose("approach"))
        if math.dist(grasp.pose.position, grasp.approach.position) < _MIN_APPROACH:
            g.fail(
                f"an approach {_MIN_APPROACH * 1000:.0f} mm or more from the pose", key="approach"
            )
        grasps.append(grasp)
    return tuple(grasps)


def _parse_model(f: JsonReader, directory: Path) -> ObjectModelSpec:
    f.as_object()
    f.check_version((FORMAT_VERSION,))
    name = f.text("name")
    if name != directory.name:
        f.fail(f"the folder's name {directory.name!r}", key="name")
    mesh_file = directory / f.text("mesh")
    if not mesh_file.is_file():
        f.fail(f"a file in {directory}", key="mesh")
    dimensions = f.vector3("dimensions")
    if min(dimensions) <= 0:
        f.fail("three sizes above 0 m", key="dimensions")
    return ObjectModelSpec(
        name=name,
        directory=directory,
        mesh_file=mesh_file,
        collision=_parse_collision(f.child("collision", optional=False)),
        mass=f.number("mass", lo=0.0, above=True),
        center_of_mass=f.vector3("center_of_mass", (0.0, 0.0, dimensions[2] / 2)),
        dimensions=dimensions,
        symmetry=_parse_symmetry(f.child("symmetry")) if f.has("symmetry") else Symmetry(),
        markers=_parse_markers(f),
        color=f.vector4("color", (0.7, 0.7, 0.7, 1.0)),
        friction=f.number("friction", 0.6, lo=0.0, above=True),
        description=f.text("description", ""),
        extra={k: v for k, v in f.as_object().items() if k not in _KNOWN_FIELDS},
        grasps=_parse_grasps(f),
    )


def parse_model(data: Any, directory: Path, file: Path | str) -> ObjectModelSpec:
    """Check and convert the content of a ``model.json``.

    Raises:
        ObjectLibraryError: a field is off; the message names ``file`` and the JSON path.
    """
    with errors_as(ObjectLibraryError):
        return _parse_model(JsonReader(data, file), directory)


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
            with errors_as(ObjectLibraryError):
                data = read_json_file(file, "object model")
            self._models[name] = parse_model(data, directory, file)
        return self._models[name]
