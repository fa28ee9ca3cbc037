"""The simulated 2D wire bender of the tending task (the paper's section V-B).

A fixture of the scene (a ``wire_bender`` model) that a scene file's ``bender`` block brings
to life (see ``bender_spec``): before each part its welding arm (a ``bender_arm`` body,
kinematic: moved on the physics thread) swings down over the exit, the part (a wireform of
the object library, a scene object named ``part_001``...) drops onto the exit with some
spread, and the arm swings back. The bender has no communication port: operations learn
that a part came only by looking (the arm in an occupancy region, the part on the table).

Faults are physical, never flags an operation could read: a part with a bad weld comes
apart when it is lifted (its body is replaced by the pieces of its ``weld`` in model.json,
which fall out of the tool: the gripper closes on nothing), and a bad grasp slips (the
tool's hold on the part lets go and the part drops). What the bender made and what broke is
recorded with simulated times for tests and scores (:meth:`WireBender.produced`,
:meth:`WireBender.events`): ground truth, never for an operation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capabilities.bullet import pybullet as p
from capabilities.geometry import quaternion_to_matrix
from capabilities.sim.bender_spec import (
    BenderSpec,
    FaultModel,
    PlannedPart,
    parse_bender,
    plan_parts,
)
from capabilities.sim.objects import ObjectModelSpec, SceneError, set_object_frame_pose, wake
from capabilities.sim.scene import SceneState
from capabilities.sim.scene_spec import read_scene_json
from capabilities.sim.schedule import ScheduledActor
from engine.json_reader import JsonFileError, JsonReader
from engine.types import Pose

__all__ = ["BenderEvent", "WireBender", "install_scene_bender", "read_bender"]

RELEASED, WELD_BROKE, SLIPPED = "released", "weld_broke", "slipped"
ARM = "bender_arm"  # the scene object name of the welding arm
SLIP = 0.02  # m a slipping part slides down the fingers: out of 15 mm long fingertips
RESTING_SPEED = 0.01  # m/s: a released part slower than this has landed...
SETTLE = 0.3  # s: ...once it had this long to fall


@dataclass(frozen=True)
class BenderEvent:
    """What happened at simulated time ``time`` (ground truth, for tests and scores).

    ``kind`` is released (a part dropped onto the exit at ``pose``), weld_broke (a bad
    weld came apart while lifted) or slipped (a bad grasp let the part go).
    """

    time: float
    kind: str
    part: str
    shape: str
    bad_weld: bool
    bad_grasp: bool
    pose: Pose | None = None


@dataclass
class _Live:
    """A released part the bender still watches for its fault."""

    planned: PlannedPart
    released: float  # simulated time
    rest: float | None = None  # its height once it came to rest (m above the table)


def read_bender(path: Path | str) -> BenderSpec | None:
    """The bender block of a scene file (None if it has none); raises SceneFileError."""
    return parse_bender(read_scene_json(path), str(path))


def _pitch_pose(pivot: Pose, pitch: float) -> Pose:
    """The arm's frame: at the pivot, turned by ``pitch`` about the bender's y."""
    return pivot.compose(
        Pose((0.0, 0.0, 0.0), (0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2)))
    )


def _smooth(u: float) -> float:
    u = min(1.0, max(0.0, u))
    return u * u * (3 - 2 * u)


class WireBender(ScheduledActor[PlannedPart, BenderEvent]):
    """Runs the bender on the physics thread of a SimCell.

    Args:
        spec: the scene's bender block.
        scene: the loaded scene (with the bender fixture).
        seed: the scene's seed (None: not reproducible).
        faults: fault rates instead of the scene's (a run sets them).
    """

    def __init__(
        self,
        spec: BenderSpec,
        scene: SceneState,
        seed: int | None,
        faults: FaultModel | None = None,
    ) -> None:
        super().__init__(plan_parts(spec, seed, faults))
        self.spec = spec
        self._scene = scene
        self._machine = _machine(scene.model(spec.fixture))
        self._station: dict[str, Pose] = {}
        for shape in spec.shapes:
            model = scene.library.get(shape)
            if "weld" not in model.extra:
                raise SceneError(f"model {shape!r} is no wireform (it has no weld)")
            self._station[shape] = _weld_station(model)
        self._live: dict[str, _Live] = {}
        self._pitch = self._machine.rest_pitch
        self._next_release = 0
        self._pieces: list[int] = []

    def produced(self) -> list[BenderEvent]:
        """The parts released so far (ground truth, for scores)."""
        return [e for e in self.events() if e.kind == RELEASED]

    def release_times(self) -> list[float]:
        """Simulated times at which parts are (or will be) released (after ``install``)."""
        start = self.start_time or 0.0
        return [start + planned.offset for planned in self.plan]

    def pieces(self) -> list[int]:
        """Bodies of the pieces of broken welds (ground truth)."""
        return list(self._pieces)

    # ------------------------------------------------------------------ physics thread

    def _machine_pose(self) -> Pose:
        return self._scene.truth_pose(self._client, self.spec.fixture)

    def _attached(self, client: int) -> None:
        if ARM not in self._scene.objects:
            pose = _pitch_pose(self._pivot(), self._pitch)
            self._scene.spawn(client, ARM, self._machine.arm_model, pose, fixed=True)

    def _pivot(self) -> Pose:
        return self._machine_pose().compose(Pose(self._machine.pivot))

    def _act(self, planned: PlannedPart, now: float) -> BenderEvent:
        dx, dy, dyaw = planned.shift
        (ex, ey), drop = self._machine.exit, self._machine.drop_height
        local = Pose((ex + dx, ey + dy, drop), (0.0, 0.0, math.sin(dyaw / 2), math.cos(dyaw / 2)))
        pose = self._machine_pose().compose(local).compose(self._station[planned.shape])
        self._scene.spawn(self._client, planned.name, planned.shape, pose)
        if planned.bad_weld or planned.bad_grasp:
            self._live[planned.name] = _Live(planned, now)
        return self._event(now, RELEASED, planned, pose)

    @staticmethod
    def _event(now: float, kind: str, planned: PlannedPart, pose: Pose | None) -> BenderEvent:
        return BenderEvent(
            now, kind, planned.name, planned.shape, planned.bad_weld, planned.bad_grasp, pose
        )

    def _each_step(self, elapsed: float, now: float) -> None:
        self._move_arm(elapsed)
        for name, live in list(self._live.items()):
            self._watch(name, live, now)

    def _height(self, name: str) -> float:
        return self._scene.truth_pose(self._client, name).position[2] - self._scene.table_top_z

    def _arm_pitch(self, elapsed: float) -> float:
        """The arm's pitch at ``elapsed`` seconds: down before each release, back after."""
        plan, spec = self.plan, self.spec
        while (
            self._next_release < len(plan)
            and plan[self._next_release].offset + spec.hold + spec.swing < elapsed
        ):
            self._next_release += 1
        rest, low = self._machine.rest_pitch, self._machine.release_pitch
        if self._next_release >= len(plan):
            return rest
        at = plan[self._next_release].offset
        if elapsed < at:
            down = _smooth((elapsed - (at - spec.swing)) / spec.swing)
        else:
            down = 1.0 - _smooth((elapsed - at - spec.hold) / spec.swing)
        return rest + (low - rest) * down

    def _move_arm(self, elapsed: float) -> None:
        pitch = self._arm_pitch(elapsed)
        if abs(pitch - self._pitch) < 1e-6:
            return
        self._pitch = pitch
        arm = self._scene.objects[ARM]
        set_object_frame_pose(
            self._client, arm.body_id, arm.model, _pitch_pose(self._pivot(), pitch)
        )
        # A moved fixture pushes nothing that sleeps: wake what the arm's box now touches.
        lo, hi = p.getAABB(arm.body_id, physicsClientId=self._client)
        for body, _link in p.getOverlappingObjects(lo, hi, physicsClientId=self._client) or ():
            if body != arm.body_id:
                wake(self._client, body)

    def _watch(self, name: str, live: _Live, now: float) -> None:
        """Break a bad part's weld, or let a bad grasp slip, once it is lifted."""
        if name not in self._scene.objects:  # taken out of the cell
            del self._live[name]
            return
        height = self._height(name)
        if live.rest is None:  # falling onto the exit (or onto a part there)
            body = self._scene.body_id(name)
            velocity = p.getBaseVelocity(body, physicsClientId=self._client)[0]
            if now - live.released > SETTLE and math.dist(velocity, (0, 0, 0)) < RESTING_SPEED:
                live.rest = height
            return
        if height < live.rest + self.spec.lift:
            return
        planned = live.planned
        del self._live[name]
        if planned.bad_weld:
            pose = self._scene.truth_pose(self._client, name)
            self._break(name)
            self._record(self._event(now, WELD_BROKE, planned, pose))
        else:
            self._slip(name)
            self._record(self._event(now, SLIPPED, planned, None))

    def _holds_on(self, body: int) -> list[int]:
        """The constraints that hold ``body`` (a tool's attachment)."""
        client, found = self._client, []
        for i in range(p.getNumConstraints(physicsClientId=client)):
            uid = p.getConstraintUniqueId(i, physicsClientId=client)
            info = p.getConstraintInfo(uid, physicsClientId=client)
            if body in (info[0], info[2]):
                found.append(uid)
        return found

    def _slip(self, name: str) -> None:
        """The grasp lets go: the tool's hold on the part is gone and the part slides
        ``SLIP`` down, out of the fingers, and falls.
        """
        client, body, model = self._client, self._scene.body_id(name), self._scene.model(name)
        for uid in self._holds_on(body):
            p.removeConstraint(uid, physicsClientId=client)
        pose = self._scene.truth_pose(client, name)
        x, y, z = pose.position
        set_object_frame_pose(client, body, model, Pose((x, y, z - SLIP), pose.orientation))

    def _break(self, name: str) -> None:
        """Replace the part by its weld's pieces, the weld bead gone (they fall apart)."""
        client, model = self._client, self._scene.model(name)
        body = self._scene.body_id(name)
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        velocity = p.getBaseVelocity(body, physicsClientId=client)
        frame = Pose(pos, orn).compose(Pose(model.center_of_mass).inverse())
        self._scene.remove(client, name)
        for boxes in model.extra["weld"]["pieces"]:
            piece = _spawn_piece(client, model, [int(b) for b in boxes], frame)
            p.resetBaseVelocity(piece, velocity[0], velocity[1], physicsClientId=client)
            self._pieces.append(piece)


@dataclass(frozen=True)
class _Machine:
    """A wire bender model's ``welding_arm`` and ``exit`` (bender frame, m and rad)."""

    arm_model: str
    pivot: tuple[float, float, float]
    rest_pitch: float
    release_pitch: float
    exit: tuple[float, float]
    drop_height: float


def _machine(model: ObjectModelSpec) -> _Machine:
    """The bender geometry of a model; SceneError names the model.json and what is off."""
    r = JsonReader(model.extra, str(model.directory / "model.json"))
    try:
        arm, exit_ = r.child("welding_arm", optional=False), r.child("exit", optional=False)
        return _Machine(
            arm.text("model", nonempty=True),
            arm.vector3("pivot"),
            arm.number("rest_pitch"),
            arm.number("release_pitch"),
            exit_.vector2("position"),
            exit_.number("drop_height", 0.03, lo=0.0, hi=0.5),
        )
    except JsonFileError as exc:
        raise SceneError(f"model {model.name!r} is no wire bender: {exc}") from exc


def _weld_station(model: ObjectModelSpec) -> Pose:
    """Where the bender holds a part while it welds, as the part's frame in the exit's: its
    weld bead (where the gripper's grasp closes) lies on the exit point, turned so that the
    grasp's fingers close along the exit's y, whatever the shape (one pick waypoint takes
    every shape).
    """
    grasp = next((g for g in model.grasps if g.tool == "gripper"), model.grasp())
    x, y, _ = grasp.pose.position
    tool_x = quaternion_to_matrix(grasp.pose.orientation)[:, 0]
    yaw = math.atan2(tool_x[1], tool_x[0])
    held = Pose((x, y, 0.0), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
    return held.inverse()


def _spawn_piece(client: int, model: ObjectModelSpec, boxes: list[int], frame: Pose) -> int:
    """A body made of some of a wireform's boxes, placed as they were in the part."""
    parts = [model.collision.boxes[i] for i in boxes]
    half = [[s / 2 for s in b.size] for b in parts]
    where = [list(b.position) for b in parts]
    col = p.createCollisionShapeArray(
        shapeTypes=[p.GEOM_BOX] * len(parts),
        halfExtents=half,
        collisionFramePositions=where,
        physicsClientId=client,
    )
    vis = p.createVisualShapeArray(
        shapeTypes=[p.GEOM_BOX] * len(parts),
        halfExtents=half,
        visualFramePositions=where,
        rgbaColors=[list(model.color)] * len(parts),
        physicsClientId=client,
    )
    volumes = [b.size[0] * b.size[1] * b.size[2] for b in parts]
    total = sum(b.size[0] * b.size[1] * b.size[2] for b in model.collision.boxes)
    # Its centre of mass is the middle of its own wire, not the part's frame: with the mass
    # at the frame (off an L-shaped piece) the piece toppled onto its edge into the surface.
    centroid = [
        sum(v * w[i] for v, w in zip(volumes, where, strict=True)) / sum(volumes) for i in range(3)
    ]
    return int(
        p.createMultiBody(
            baseMass=model.mass * sum(volumes) / total,
            baseCollisionShapeIndex=col,
            baseVisualShapeIndex=vis,
            basePosition=list(frame.position),
            baseOrientation=list(frame.orientation),
            baseInertialFramePosition=centroid,
            physicsClientId=client,
        )
    )


def install_scene_bender(
    cell: Any,
    scene: SceneState,
    path: Path | str,
    seed: int | None,
    faults: FaultModel | None = None,
    start: bool = True,
) -> WireBender | None:
    """Make (and with ``start`` start) the bender of a scene file; None when it has none."""
    spec = read_bender(path)
    if spec is None:
        return None
    bender = WireBender(spec, scene, seed, faults)
    bender.install(cell, start)
    return bender
