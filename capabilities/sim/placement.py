"""Seeded random placement of a scene's objects on the table.

Objects are rectangles (their bounding box turned by their yaw); reserved areas and fixed
markers are circles. A pose fits when the rectangle lies on the table, its centre is within
the robot's reach, and it keeps ``clearance`` from everything placed before it. Placement is
sequential rejection sampling; when an object finds no room, the whole scene is drawn again
(up to ``_ROUNDS`` times), all from one ``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from capabilities.sim.markers_texture import plane_side
from capabilities.sim.objects import ObjectLibrary, ObjectModelSpec, SceneError
from capabilities.sim.scene_spec import ObjectEntry, SceneSpec

__all__ = ["Placement", "sample_placements"]

_ROUNDS = 20


@dataclass(frozen=True)
class Placement:
    """Where an object was put on the table: centre (x, y) and yaw (rad)."""

    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class _Rect:
    x: float
    y: float
    yaw: float
    hx: float
    hy: float
    what: str

    def corners(self) -> np.ndarray:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [self.hx, self.hy]
        return local @ np.array([[c, s], [-s, c]]) + [self.x, self.y]

    def axes(self) -> list[np.ndarray]:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return [np.array([c, s]), np.array([-s, c])]

    def distance_to_point(self, px: float, py: float) -> float:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        dx, dy = px - self.x, py - self.y
        lx, ly = abs(c * dx + s * dy) - self.hx, abs(-s * dx + c * dy) - self.hy
        return math.hypot(max(lx, 0.0), max(ly, 0.0))


@dataclass(frozen=True)
class _Circle:
    x: float
    y: float
    r: float
    what: str


def _apart(a: _Rect, b: _Rect | _Circle, clearance: float) -> bool:
    """True when ``a`` and ``b`` keep ``clearance`` (separating axes; a little conservative)."""
    if isinstance(b, _Circle):
        return a.distance_to_point(b.x, b.y) >= b.r + clearance
    pa, pb = a.corners(), b.corners()
    for axis in a.axes() + b.axes():
        ia, ib = pa @ axis, pb @ axis
        if ib.min() - ia.max() >= clearance or ia.min() - ib.max() >= clearance:
            return True
    return False


def _fixed_obstacles(
    spec: SceneSpec, keep_out: tuple[tuple[float, float, float], ...]
) -> list[_Rect | _Circle]:
    out: list[_Rect | _Circle] = [
        _Circle(k.position[0], k.position[1], k.radius, f"reserved area {k.name!r}")
        for k in spec.reserved
    ]
    out += [_Circle(x, y, r, "a keep-out area of the cell") for x, y, r in keep_out]
    for m in spec.markers:
        half = plane_side(m.size) / 2
        out.append(_Rect(m.position[0], m.position[1], m.yaw, half, half, f"marker {m.name!r}"))
    return out


def _problem(spec: SceneSpec, entry: ObjectEntry, rect: _Rect, taken: list[_Rect | _Circle]) -> str:
    """Why ``rect`` does not fit, or '' when it does."""
    t = spec.table
    corners = rect.corners() - t.center
    if (np.abs(corners) > np.array(t.size[:2]) / 2).any():
        return "it is not fully on the table"
    if not entry.fixed and not spec.reach.contains(rect.x, rect.y):
        return "it is out of the robot's reach"
    for other in taken:
        if not _apart(rect, other, spec.clearance):
            return f"it overlaps {other.what}"
    return ""


def _draw(entry: ObjectEntry, model: ObjectModelSpec, rng: np.random.Generator) -> _Rect:
    values = [
        rng.uniform(*entry.random[k]) if k in entry.random else nominal
        for k, nominal in (("x", entry.position[0]), ("y", entry.position[1]), ("yaw", entry.yaw))
    ]
    hx, hy = model.dimensions[0] / 2, model.dimensions[1] / 2
    return _Rect(values[0], values[1], values[2], hx, hy, f"object {entry.name!r}")


def _one_round(
    spec: SceneSpec,
    models: list[ObjectModelSpec],
    rng: np.random.Generator,
    fixed: list[_Rect | _Circle],
) -> tuple[dict[str, Placement | None], str]:
    """Place every object once; returns the placements and '' or why an object found no room."""
    taken = list(fixed)
    out: dict[str, Placement | None] = {}
    for entry, model in zip(spec.objects, models, strict=True):
        if not rng.random() < entry.present_probability:
            out[entry.name] = None
            continue
        for _ in range(spec.max_tries if entry.random else 1):
            rect = _draw(entry, model, rng)
            why = _problem(spec, entry, rect, taken)
            if not why:
                break
        else:
            if not entry.random:
                return out, f"object {entry.name!r} does not fit at its nominal pose: {why}"
            return out, f"object {entry.name!r} found no room in {spec.max_tries} tries"
        out[entry.name] = Placement(rect.x, rect.y, rect.yaw)
        taken.append(rect)
    return out, ""


def sample_placements(
    spec: SceneSpec,
    library: ObjectLibrary,
    seed: int | None,
    keep_out: tuple[tuple[float, float, float], ...] = (),
) -> dict[str, Placement | None]:
    """Draw the pose of every object of a scene (None when it is absent this time).

    Args:
        spec: the scene.
        library: where the objects' models (their sizes) come from.
        seed: same seed, same placements (None: fresh entropy).
        keep_out: more circles (x, y, radius) to keep free.

    Raises:
        SceneError: an object does not fit at its nominal pose, or random draws found no
            room for every object.
    """
    rng = np.random.default_rng(seed)
    models = [library.get(entry.model) for entry in spec.objects]
    fixed = _fixed_obstacles(spec, keep_out)
    why = ""
    for _ in range(_ROUNDS):
        out, why = _one_round(spec, models, rng, fixed)
        if not why:
            return out
        if "nominal" in why:
            break
    raise SceneError(f"{spec.source}: cannot place the objects: {why}")
