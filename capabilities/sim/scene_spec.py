"""Scene files of the simulated cell (``resources/scenes/*.json``, format_version 1).

A scene file describes the table, fixed markers, areas to keep free, objects and their
randomisation; ``capabilities.sim.scene.load_scene`` builds it in pybullet. Fields:

- ``name``, ``description``
- ``table``: ``center`` [x, y], ``size`` [x, y, height] (it reaches from its top down by
  ``height``), ``top_z``, ``color`` RGBA, ``floor`` (bool: a floor under the table)
- ``markers``: fixed ArUco markers lying flat on the table: ``name``, ``id``, ``size`` (m,
  black border included), ``position`` [x, y], ``yaw`` (rad; 0 puts the texture's top
  toward world +y)
- ``reserved``: circles to keep free (e.g. the suction-tool holster): ``name``,
  ``position`` [x, y], ``radius``, ``note``
- ``objects`` and ``fixtures`` (fixtures do not move): ``name`` (unique), ``model`` (a
  library model), ``position`` [x, y], ``yaw``; optional ``random`` with ``x``, ``y``,
  ``yaw`` ranges ``[lo, hi]`` (world x, y in m and yaw in rad, replacing the nominal
  value) and ``present_probability`` (0..1, default 1)
- ``placement``: ``clearance`` (m between footprints), ``max_tries``, and ``reach``:
  ``center`` [x, y] of the robot base, ``min_radius``, ``max_radius`` and ``max_angle``
  (rad either side of +x) that objects' centres must be within.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from capabilities.sim.objects import SceneError
from engine.json_reader import JsonReader, errors_as, read_json_file

__all__ = [
    "FORMAT_VERSION",
    "KeepOut",
    "MarkerEntry",
    "ObjectEntry",
    "ReachSpec",
    "SceneFileError",
    "SceneSpec",
    "TableSpec",
    "parse_block",
    "parse_scene",
    "read_scene",
    "read_scene_json",
]

FORMAT_VERSION = 1

T = TypeVar("T")


class SceneFileError(SceneError):
    """A scene file is missing or malformed; the message names the file and JSON path.

    It wraps the reader's :class:`engine.json_reader.JsonFileError` (its ``__cause__``).
    """


@dataclass(frozen=True)
class TableSpec:
    """The table box: top centre (x, y, top_z) and size (x, y, height)."""

    center: tuple[float, float] = (0.55, 0.0)
    size: tuple[float, float, float] = (0.8, 1.2, 0.75)
    top_z: float = 0.0
    color: tuple[float, float, float, float] = (0.72, 0.62, 0.50, 1.0)
    floor: bool = True


@dataclass(frozen=True)
class MarkerEntry:
    """A fixed marker lying on the table."""

    name: str
    marker_id: int
    size: float
    position: tuple[float, float]
    yaw: float = 0.0


@dataclass(frozen=True)
class KeepOut:
    """A circle on the table that no object may cover."""

    name: str
    position: tuple[float, float]
    radius: float
    note: str = ""


@dataclass(frozen=True)
class ObjectEntry:
    """An object (or fixture) of the scene and how it is randomised."""

    name: str
    model: str
    position: tuple[float, float]
    yaw: float = 0.0
    random: dict[str, tuple[float, float]] = field(default_factory=dict)
    present_probability: float = 1.0
    fixed: bool = False


@dataclass(frozen=True)
class ReachSpec:
    """Where object centres must be for the robot to reach them."""

    center: tuple[float, float] = (0.0, 0.0)
    min_radius: float = 0.30
    max_radius: float = 0.75
    max_angle: float = math.radians(70.0)

    def contains(self, x: float, y: float) -> bool:
        """True when (x, y) is within the reach annulus and angle."""
        dx, dy = x - self.center[0], y - self.center[1]
        r = math.hypot(dx, dy)
        in_angle = abs(math.atan2(dy, dx)) <= self.max_angle
        return self.min_radius <= r <= self.max_radius and in_angle


@dataclass(frozen=True)
class SceneSpec:
    """A parsed scene file."""

    name: str
    source: str
    description: str = ""
    table: TableSpec = TableSpec()
    markers: tuple[MarkerEntry, ...] = ()
    reserved: tuple[KeepOut, ...] = ()
    objects: tuple[ObjectEntry, ...] = ()
    reach: ReachSpec = ReachSpec()
    clearance: float = 0.02
    max_tries: int = 200


def _table(r: JsonReader) -> TableSpec:
    d = TableSpec()
    size = r.vector3("size", d.size)
    if min(size) <= 0:
        r.fail("three sizes above 0 m", key="size")
    return TableSpec(
        center=r.vector2("center", d.center),
        size=size,
        top_z=r.number("top_z", d.top_z),
        color=r.vector4("color", d.color),
        floor=r.flag("floor", d.floor),
    )


def _marker(r: JsonReader) -> MarkerEntry:
    return MarkerEntry(
        name=r.text("name"),
        marker_id=r.integer("id", lo=0, hi=49),
        size=r.number("size", lo=1e-3, hi=1.0),
        position=r.vector2("position"),
        yaw=r.number("yaw", 0.0),
    )


def _object(r: JsonReader, fixed: bool) -> ObjectEntry:
    ranges: dict[str, tuple[float, float]] = {}
    for key, span in r.entries("random", "ranges"):
        if key not in ("x", "y", "yaw"):
            span.fail("one of x, y, yaw", repr(key))
        lo, hi = span.as_vector(2)
        if lo > hi:
            span.fail("a range [lo, hi] with lo <= hi")
        ranges[key] = (lo, hi)
    return ObjectEntry(
        name=r.text("name"),
        model=r.text("model"),
        position=r.vector2("position"),
        yaw=r.number("yaw", 0.0),
        random=ranges,
        present_probability=r.number("present_probability", 1.0, lo=0.0, hi=1.0),
        fixed=fixed,
    )


def _keep_out(r: JsonReader) -> KeepOut:
    return KeepOut(
        r.text("name"), r.vector2("position"), r.number("radius", lo=0.0), r.text("note", "")
    )


def _reach(r: JsonReader) -> ReachSpec:
    d = ReachSpec()
    return ReachSpec(
        center=r.vector2("center", d.center),
        min_radius=r.number("min_radius", d.min_radius, lo=0.0),
        max_radius=r.number("max_radius", d.max_radius, lo=0.0),
        max_angle=r.number("max_angle", d.max_angle, lo=0.0, hi=math.pi),
    )


def _scene(r: JsonReader) -> SceneSpec:
    r.check_version((FORMAT_VERSION,))
    placement = r.child("placement")
    objects = tuple(_object(o, False) for o in r.items("objects", "objects"))
    objects += tuple(_object(o, True) for o in r.items("fixtures", "fixtures"))
    seen: set[str] = set()
    for entry in objects:
        if entry.name in seen or entry.name == "table":
            r.fail("unique object names other than 'table'", f"{entry.name!r} again", "objects")
        seen.add(entry.name)
    return SceneSpec(
        name=r.text("name"),
        source=r.file,
        description=r.text("description", ""),
        table=_table(r.child("table")),
        markers=tuple(_marker(m) for m in r.items("markers", "markers")),
        reserved=tuple(_keep_out(k) for k in r.items("reserved", "circles")),
        objects=objects,
        reach=_reach(placement.child("reach")),
        clearance=placement.number("clearance", 0.02, lo=0.0),
        max_tries=placement.integer("max_tries", 200, lo=1),
    )


def parse_scene(data: Any, source: str = "<scene>") -> SceneSpec:
    """Check and convert the JSON content of a scene file.

    Raises:
        SceneFileError: a field is off; the message names ``source`` and the JSON path.
    """
    with errors_as(SceneFileError):
        return _scene(JsonReader(data, source))


def read_scene(scene: Path | str | dict[str, Any] | SceneSpec) -> SceneSpec:
    """A SceneSpec from a path, a parsed JSON dict or a SceneSpec (returned as is).

    Raises:
        SceneFileError: the file is missing, not JSON or off; the message names the file as
            given, the JSON path (or line and column) and what was expected.
    """
    if isinstance(scene, SceneSpec):
        return scene
    if isinstance(scene, dict):
        return parse_scene(scene, "<scene dict>")
    return parse_scene(read_scene_json(scene), str(scene))


def parse_block(
    data: Any, source: str, name: str, fields: tuple[str, ...], build: Callable[[JsonReader], T]
) -> T | None:
    """``build`` of the block ``name`` of a parsed scene file (with ``fields``); None without one.

    Raises:
        SceneFileError: the block is off; the message names ``source`` and the JSON path.
    """
    if not isinstance(data, dict) or name not in data:
        return None
    with errors_as(SceneFileError):
        return build(JsonReader(data, source).child(name, fields, optional=False))


def read_scene_json(path: Path | str) -> Any:
    """The parsed JSON of a scene file; raises SceneFileError (missing, not JSON)."""
    with errors_as(SceneFileError):
        return read_json_file(path, "scene")
