"""The simulated worker: a person at the simulated cell, driven by the scene file.

An optional ``worker`` block of a scene file says what the person does; the times and poses
are drawn once, from the scene's seed, when the worker is made (same seed, same worker)::

    "worker": {
      "handoffs": [
        {"object": "kit_bin", "model": "kit_bin",
         "area": {"x": [0.5, 0.62], "y": [0.2, 0.32], "yaw": [-0.3, 0.3]},
         "place_at": [1.0, 4.0], "hold": [3.0, 6.0], "cycles": 1, "gap": [2.0, 4.0],
         "drop_height": 0.01}
      ],
      "nudges": [{"object": "cup", "at": [2.0, 6.0], "shift": [0.02, 0.05]}]
    }

A handoff puts the object (named ``object``, of library model ``model``) at a pose drawn in
``area`` (world x, y in m, yaw in rad) ``place_at`` seconds after the worker starts, and
takes it away ``hold`` seconds later; ``cycles`` repeats that after ``gap`` seconds. A hand
is not simulated: the object appears ``drop_height`` above the table and settles. A nudge
shifts a resting object by ``shift`` metres in a random direction (a person moving it while
the robot works); an object that is not resting on the table (held) is left alone.

The worker acts on the physics thread (a step hook) at simulated times and records what it
did, with those times, for tests and scores: :meth:`SimWorker.events` (the mechanism is
:class:`capabilities.sim.schedule.ScheduledActor`, shared with the wire bender).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from capabilities.sim.objects import object_frame_pose, set_object_frame_pose
from capabilities.sim.scene import SceneState, yaw_pose
from capabilities.sim.scene_spec import parse_block, read_scene_json
from capabilities.sim.schedule import ScheduledActor
from engine.json_reader import JsonReader
from engine.types import Pose

__all__ = [
    "HandoffSpec",
    "NudgeSpec",
    "PlannedEvent",
    "SimWorker",
    "WorkerEvent",
    "WorkerSpec",
    "install_scene_worker",
    "parse_worker",
    "read_worker",
]

PLACED, TAKEN, MOVED, SKIPPED = "placed", "taken", "moved", "skipped"
# An object whose bottom is higher than this above the table is not resting there (held).
RESTING_TOLERANCE = 0.01
Range = tuple[float, float]


@dataclass(frozen=True)
class HandoffSpec:
    """An object a person hands into the cell and takes back (see the module doc)."""

    object: str
    model: str
    area: dict[str, Range]
    place_at: Range
    hold: Range
    cycles: int = 1
    gap: Range = (2.0, 4.0)
    drop_height: float = 0.01


@dataclass(frozen=True)
class NudgeSpec:
    """A resting object a person shifts by a few centimetres."""

    object: str
    at: Range
    shift: Range


@dataclass(frozen=True)
class WorkerSpec:
    """The ``worker`` block of a scene: the person's hand-offs and nudges."""

    handoffs: tuple[HandoffSpec, ...] = ()
    nudges: tuple[NudgeSpec, ...] = ()


@dataclass(frozen=True)
class PlannedEvent:
    """What the worker will do: ``offset`` seconds after it starts."""

    offset: float
    kind: str  # placed, taken or moved
    object: str
    model: str = ""
    pose: Pose | None = None  # where a handoff puts the object (on the table)
    shift: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class WorkerEvent:
    """What the worker did, at simulated time ``time``; ``pose`` is ground truth."""

    time: float
    kind: str  # placed, taken, moved or skipped
    object: str
    pose: Pose | None = None
    note: str = ""


def _range(r: JsonReader, key: str, lo: float = 0.0, default: Range | None = None) -> Range:
    a, b = r.vector2(key, default)
    if not lo <= a <= b:
        r.fail(f"a range [lo, hi] with {lo:g} <= lo <= hi", key=key)
    return a, b


def _handoff(r: JsonReader) -> HandoffSpec:
    area = r.child("area")
    ranges = {}
    for key in ("x", "y", "yaw"):
        ranges[key] = _range(area, key, -math.inf, (0.0, 0.0) if key == "yaw" else None)
    return HandoffSpec(
        object=r.text("object"),
        model=r.text("model"),
        area=ranges,
        place_at=_range(r, "place_at"),
        hold=_range(r, "hold"),
        cycles=r.integer("cycles", 1, lo=1),
        gap=_range(r, "gap", default=(2.0, 4.0)),
        drop_height=r.number("drop_height", 0.01, lo=0.0, hi=0.5),
    )


def _nudge(r: JsonReader) -> NudgeSpec:
    return NudgeSpec(r.text("object"), _range(r, "at"), _range(r, "shift"))


def parse_worker(data: Any, source: str = "<scene>") -> WorkerSpec | None:
    """The ``worker`` block of a parsed scene file, or None if it has none.

    Raises:
        SceneFileError: the block is off; the message names ``source`` and the JSON path.
    """
    return parse_block(data, source, "worker", ("handoffs", "nudges"), _worker)


def _worker(block: JsonReader) -> WorkerSpec:
    return WorkerSpec(
        tuple(_handoff(h) for h in block.items("handoffs", "handoffs")),
        tuple(_nudge(n) for n in block.items("nudges", "nudges")),
    )


def read_worker(path: Path | str) -> WorkerSpec | None:
    """The worker block of a scene file (None if it has none); raises SceneFileError."""
    return parse_worker(read_scene_json(path), str(path))


def _draw(rng: np.random.Generator, span: Range) -> float:
    return float(rng.uniform(span[0], span[1])) if span[1] > span[0] else span[0]


def plan_events(spec: WorkerSpec, seed: int | None, table_top_z: float) -> list[PlannedEvent]:
    """The worker's schedule, drawn from ``seed`` (offsets from its start, in order)."""
    rng = np.random.default_rng(None if seed is None else [seed, 7231])
    events: list[PlannedEvent] = []
    for h in spec.handoffs:
        at = _draw(rng, h.place_at)
        for _ in range(h.cycles):
            x, y = _draw(rng, h.area["x"]), _draw(rng, h.area["y"])
            pose = yaw_pose(x, y, table_top_z, _draw(rng, h.area["yaw"]))
            events.append(PlannedEvent(at, PLACED, h.object, h.model, pose))
            at += _draw(rng, h.hold)
            events.append(PlannedEvent(at, TAKEN, h.object))
            at += _draw(rng, h.gap)
    for n in spec.nudges:
        angle, dist = float(rng.uniform(-math.pi, math.pi)), _draw(rng, n.shift)
        shift = (dist * math.cos(angle), dist * math.sin(angle))
        events.append(PlannedEvent(_draw(rng, n.at), MOVED, n.object, shift=shift))
    return sorted(events, key=lambda e: e.offset)


class SimWorker(ScheduledActor[PlannedEvent, WorkerEvent]):
    """Carries out a worker's schedule on the physics thread of a SimCell.

    Args:
        spec: what the worker does.
        scene: the loaded scene (objects are spawned into and removed from it).
        seed: the scene's seed (None: not reproducible).
    """

    def __init__(self, spec: WorkerSpec, scene: SceneState, seed: int | None) -> None:
        super().__init__(plan_events(spec, seed, scene.table_top_z))
        self.spec = spec
        self._scene = scene
        self._drop = {h.object: h.drop_height for h in spec.handoffs}

    def planned_times(self) -> list[tuple[float, str, str]]:
        """(simulated time, kind, object) of every planned event (after ``install``)."""
        start = self.start_time or 0.0
        return [(start + e.offset, e.kind, e.object) for e in self.plan]

    # ------------------------------------------------------------------ physics thread

    def _act(self, planned: PlannedEvent, now: float) -> WorkerEvent:
        scene, client, name = self._scene, self._client, planned.object
        present = name in scene.objects
        if planned.kind == PLACED:
            if present:
                return WorkerEvent(now, SKIPPED, name, note="already in the cell")
            assert planned.pose is not None
            lifted = planned.pose.compose(Pose((0.0, 0.0, self._drop.get(name, 0.0))))
            scene.spawn(client, name, planned.model, lifted)
            return WorkerEvent(now, PLACED, name, planned.pose)
        if not present:
            return WorkerEvent(now, SKIPPED, name, note=f"not in the cell to be {planned.kind}")
        if planned.kind == TAKEN:
            pose = scene.truth_pose(client, name)
            scene.remove(client, name)
            return WorkerEvent(now, TAKEN, name, pose)
        return self._nudge(planned, now)

    def _nudge(self, planned: PlannedEvent, now: float) -> WorkerEvent:
        scene, client, name = self._scene, self._client, planned.object
        pose = scene.truth_pose(client, name)
        if pose.position[2] - scene.table_top_z > RESTING_TOLERANCE:
            return WorkerEvent(now, SKIPPED, name, pose, "not resting on the table")
        x, y, z = pose.position
        moved = Pose((x + planned.shift[0], y + planned.shift[1], z), pose.orientation)
        body = scene.body_id(name)
        set_object_frame_pose(client, body, scene.model(name), moved)
        return WorkerEvent(now, MOVED, name, object_frame_pose(client, body, scene.model(name)))


def install_scene_worker(
    cell: Any, scene: SceneState, path: Path | str, seed: int | None, start: bool = True
) -> SimWorker | None:
    """Make (and with ``start`` start) the worker of a scene file; None when it has none."""
    spec = read_worker(path)
    if spec is None:
        return None
    worker = SimWorker(spec, scene, seed)
    worker.install(cell, start)
    return worker
