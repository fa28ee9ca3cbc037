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

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from capabilities.sim.objects import SceneError

__all__ = [
    "FORMAT_VERSION",
    "KeepOut",
    "MarkerEntry",
    "ObjectEntry",
    "ReachSpec",
    "SceneFileError",
    "SceneSpec",
    "TableSpec",
    "parse_scene",
    "read_scene",
]

FORMAT_VERSION = 1


class SceneFileError(SceneError):
    """A scene file is missing or malformed; the message names the file and JSON path."""


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


class _Reader:
    """Typed access to one JSON object; errors name the source and JSON path."""

    def __init__(self, data: Any, source: str, path: str) -> None:
        self.source, self.path = source, path
        if not isinstance(data, dict):
            self.fail("", "an object", data)
        self.data: dict[str, Any] = data

    def fail(self, key: str, expected: str, got: Any) -> None:
        where = f"{self.path}.{key}" if key else self.path
        got_text = repr(got) if len(repr(got)) < 60 else repr(got)[:57] + "..."
        raise SceneFileError(f"{self.source}: {where}: expected {expected}, got {got_text}")

    def get(self, key: str, default: Any = ...) -> Any:
        if key not in self.data:
            if default is ...:
                self.fail(key, "a value (missing)", None)
            return default
        return self.data[key]

    def number(
        self, key: str, default: Any = ..., lo: float = -math.inf, hi: float = math.inf
    ) -> float:
        value = self.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not lo <= value <= hi:
            self.fail(key, f"a number in [{lo}, {hi}]", value)
        return float(value)

    def numbers(self, key: str, n: int, default: Any = ...) -> tuple[float, ...]:
        value = self.get(key, default)
        ok = isinstance(value, (list, tuple)) and len(value) == n
        if not ok or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value
        ):
            self.fail(key, f"a list of {n} numbers", value)
        return tuple(float(v) for v in value)

    def text(self, key: str, default: Any = ...) -> str:
        value = self.get(key, default)
        if not isinstance(value, str):
            self.fail(key, "a text string", value)
        return str(value)

    def items(self, key: str) -> list[_Reader]:
        value = self.get(key, [])
        if not isinstance(value, list):
            self.fail(key, "a list", value)
        return [_Reader(v, self.source, f"{self.path}.{key}[{i}]") for i, v in enumerate(value)]

    def child(self, key: str) -> _Reader:
        return _Reader(self.get(key, {}), self.source, f"{self.path}.{key}")


def _table(r: _Reader) -> TableSpec:
    d = TableSpec()
    floor = r.get("floor", d.floor)
    if not isinstance(floor, bool):
        r.fail("floor", "true or false", floor)
    size = r.numbers("size", 3, d.size)
    if min(size) <= 0:
        r.fail("size", "three sizes above 0 m", list(size))
    return TableSpec(
        center=r.numbers("center", 2, d.center),  # type: ignore[arg-type]
        size=size,  # type: ignore[arg-type]
        top_z=r.number("top_z", d.top_z),
        color=r.numbers("color", 4, d.color),  # type: ignore[arg-type]
        floor=floor,
    )


def _marker(r: _Reader) -> MarkerEntry:
    marker_id = r.get("id")
    if isinstance(marker_id, bool) or not isinstance(marker_id, int) or not 0 <= marker_id < 50:
        r.fail("id", "a DICT_4X4_50 marker id (0..49)", marker_id)
    return MarkerEntry(
        name=r.text("name"),
        marker_id=marker_id,
        size=r.number("size", lo=1e-3, hi=1.0),
        position=r.numbers("position", 2),  # type: ignore[arg-type]
        yaw=r.number("yaw", 0.0),
    )


def _object(r: _Reader, fixed: bool) -> ObjectEntry:
    rnd = r.child("random")
    ranges: dict[str, tuple[float, float]] = {}
    for key in rnd.data:
        if key not in ("x", "y", "yaw"):
            rnd.fail(key, "one of x, y, yaw", key)
        lo, hi = rnd.numbers(key, 2)
        if lo > hi:
            rnd.fail(key, "a range [lo, hi] with lo <= hi", [lo, hi])
        ranges[key] = (lo, hi)
    return ObjectEntry(
        name=r.text("name"),
        model=r.text("model"),
        position=r.numbers("position", 2),  # type: ignore[arg-type]
        yaw=r.number("yaw", 0.0),
        random=ranges,
        present_probability=r.number("present_probability", 1.0, lo=0.0, hi=1.0),
        fixed=fixed,
    )


def _keep_out(r: _Reader) -> KeepOut:
    x, y = r.numbers("position", 2)
    return KeepOut(r.text("name"), (x, y), r.number("radius", lo=0.0), r.text("note", ""))


def _reach(r: _Reader) -> ReachSpec:
    d = ReachSpec()
    return ReachSpec(
        center=r.numbers("center", 2, d.center),  # type: ignore[arg-type]
        min_radius=r.number("min_radius", d.min_radius, lo=0.0),
        max_radius=r.number("max_radius", d.max_radius, lo=0.0),
        max_angle=r.number("max_angle", d.max_angle, lo=0.0, hi=math.pi),
    )


def parse_scene(data: Any, source: str = "<scene>") -> SceneSpec:
    """Check and convert the JSON content of a scene file; raise SceneFileError."""
    r = _Reader(data, source, "$")
    if r.get("format_version") != FORMAT_VERSION:
        r.fail("format_version", str(FORMAT_VERSION), r.get("format_version"))
    placement = r.child("placement")
    max_tries = placement.get("max_tries", 200)
    if isinstance(max_tries, bool) or not isinstance(max_tries, int) or max_tries < 1:
        placement.fail("max_tries", "a whole number of 1 or more", max_tries)
    objects = tuple(_object(o, False) for o in r.items("objects"))
    objects += tuple(_object(o, True) for o in r.items("fixtures"))
    seen: set[str] = set()
    for entry in objects:
        if entry.name in seen or entry.name == "table":
            r.fail(
                "objects",
                f"unique object names other than 'table' ({entry.name!r} repeats)",
                entry.name,
            )
        seen.add(entry.name)
    return SceneSpec(
        name=r.text("name"),
        source=source,
        description=r.text("description", ""),
        table=_table(r.child("table")),
        markers=tuple(_marker(m) for m in r.items("markers")),
        reserved=tuple(_keep_out(k) for k in r.items("reserved")),
        objects=objects,
        reach=_reach(placement.child("reach")),
        clearance=placement.number("clearance", 0.02, lo=0.0),
        max_tries=max_tries,
    )


def read_scene(scene: Path | str | dict[str, Any] | SceneSpec) -> SceneSpec:
    """A SceneSpec from a path, a parsed JSON dict or a SceneSpec (returned as is)."""
    if isinstance(scene, SceneSpec):
        return scene
    if isinstance(scene, dict):
        return parse_scene(scene, "<scene dict>")
    path = Path(scene)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneFileError(f"{path}: cannot read the scene file: {exc.strerror}") from exc
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SceneFileError(f"{path}: line {exc.lineno}: not JSON: {exc.msg}") from exc
    return parse_scene(data, str(path))
