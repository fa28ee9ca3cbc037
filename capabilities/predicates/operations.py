"""Operations of the predicates capability (the paper's Predicator), all conditions.

Object poses are the world model's best detections (filled by the markers or perception
capabilities); the tool is a box at the arm's TCP pose. Every predicate answers at once
(no camera, no blocking) with a finished Job whose message says why it holds or not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import manifest, stateful
from capabilities.predicates.collision import TOOL, PredicateError
from capabilities.predicates.settings import DIRECTIONS, SETTINGS
from engine.operations import (
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    PortSpec,
    StartResult,
)
from engine.types import ObjectModel, ParamType, Pose

if TYPE_CHECKING:  # the geometry (numpy) loads with the first cell's setup
    from capabilities.predicates.state import PredicatesState

__all__ = ["capability"]

CONDITION = OperationKind.CONDITION

CAP = "predicates"
FRAMES = ("world", "robot", "object_b")


def _verdict(holds: bool, message: str) -> Job:
    """A finished job: SUCCESS (true) or FAILURE (false), with the reason."""
    job = Job()
    if holds:
        job.succeed(message)
    else:
        job.fail(message)
    return job


def _name(model: Any) -> str:
    return model.name if isinstance(model, ObjectModel) else str(model)


def _guarded(fn: Callable[[OperationCall], Job]) -> Callable[[OperationCall], StartResult]:
    def start(call: OperationCall) -> StartResult:
        try:
            return fn(call)
        except PredicateError as exc:
            raise OperationFailed(str(exc)) from exc

    return start


def _object_port(name: str, doc: str) -> PortSpec:
    return PortSpec(name, (ParamType.OBJECT,), doc=doc)


_PAIR = (
    _object_port("object_a", "the object the predicate is about"),
    _object_port("object_b", "the object it is compared with"),
)
_ONE = _object_port("object", "the object")
_FRAME = PortSpec(
    "frame",
    (ParamType.TEXT,),
    default="world",
    choices=FRAMES,
    doc="directions along the world's, the robot base's or object_b's axes",
)
_MARGIN = PortSpec(
    "margin",
    (ParamType.NUMBER,),
    default=0.01,
    unit="m",
    doc="by more than this (a tie under sensor noise is neither)",
)

RELATIONS = {
    relation: manifest(
        CAP,
        relation,
        CONDITION,
        f"True when object_a is {relation.replace('_', ' ')} object_b (centres, "
        "along the frame's axes: front +x, left +y, up +z).",
        *_PAIR,
        _FRAME,
        _MARGIN,
    )
    for relation in DIRECTIONS
}


class Relation:
    """``left_of``, ``right_of``, ``in_front_of``, ``behind``, ``up_from``, ``down_from``."""

    def __init__(self, state: PredicatesState, relation: str) -> None:
        self._state = state
        self._relation = relation
        self.start = _guarded(self._start)

    def _start(self, call: OperationCall) -> Job:
        from capabilities.predicates.geometry import box_center, offset_in_frame

        state = self._state
        state.sample()
        a, b = state.best(call.input("object_a")), state.best(call.input("object_b"))
        frame_name: str = call.input("frame")
        frame = self._frame(frame_name, b.pose)
        margin: float = call.input("margin")
        offset = offset_in_frame(
            box_center(a.pose, state.height(a.object_class)),
            box_center(b.pose, state.height(b.object_class)),
            frame,
        )
        axis, sign = DIRECTIONS[self._relation]
        along = sign * float(offset[axis])
        words = self._relation.replace("_", " ")
        return _verdict(
            along > margin,
            f"{a.object_class} is {along * 1000:.0f} mm {words} {b.object_class} "
            f"in the {frame_name.replace('_', ' ')} frame (needs more than {margin * 1000:.0f} mm)",
        )

    def _frame(self, name: str, pose_b: Pose) -> Pose:
        if name == "world":
            return Pose()
        if name == "robot":
            return self._state.robot_base()
        if name == "object_b":
            return pose_b
        raise PredicateError(f"unknown frame {name!r}; frames: {', '.join(FRAMES)}")


_WINDOW = PortSpec(
    "window",
    (ParamType.DURATION,),
    default=0.5,
    unit="s",
    doc="judge the detections of this last stretch of time",
)
_SPEED = PortSpec(
    "speed", (ParamType.NUMBER,), default=0.02, unit="m/s", doc="faster than this is moving"
)
IS_MOVING = manifest(
    CAP,
    "is_moving",
    CONDITION,
    "True when the object's detections moved faster than the speed.",
    _ONE,
    _WINDOW,
    _SPEED,
)
IS_STATIONARY = manifest(
    CAP,
    "is_stationary",
    CONDITION,
    "True when the object's detections stayed (slower than the speed); "
    "false when too few were seen.",
    _ONE,
    _WINDOW,
    _SPEED,
)


class Moving:
    """``is_moving`` (want True) or ``is_stationary`` (want False) over a time window."""

    def __init__(self, state: PredicatesState, want_moving: bool) -> None:
        self._state = state
        self._want = want_moving
        self.start = _guarded(self._start)

    def _start(self, call: OperationCall) -> Job:
        state = self._state
        state.sample()
        name = _name(call.input("object"))
        window: float = call.input("window")
        threshold: float = call.input("speed")
        motion = state.track(name).motion(call.clock() - window)
        if motion.samples < 2 or motion.span < window / 4:
            return _verdict(
                False,
                f"{name}: {motion.samples} detection(s) in the last {window:g} s, too few to tell",
            )
        moving = motion.speed > threshold
        text = (
            f"{name} moves at {motion.speed * 1000:.0f} mm/s over {motion.samples} "
            f"detections in {motion.span:.2f} s (threshold {threshold * 1000:.0f} mm/s)"
        )
        return _verdict(moving == self._want, text)


_TOLERANCE = PortSpec(
    "tolerance",
    (ParamType.NUMBER,),
    default=0.003,
    unit="m",
    doc="surfaces this close count as touching",
)
_DISTANCE = PortSpec(
    "distance",
    (ParamType.NUMBER,),
    default=0.03,
    unit="m",
    doc="surfaces this close are a near collision",
)
TOUCHING = manifest(
    CAP,
    "touching",
    CONDITION,
    "True when the two objects' shapes touch or overlap.",
    *_PAIR,
    _TOLERANCE,
)
NEAR_COLLISION = manifest(
    CAP,
    "near_collision",
    CONDITION,
    "True when the two objects' shapes are closer than the distance (touching included).",
    *_PAIR,
    _DISTANCE,
)
TOOL_TOUCHING = manifest(
    CAP,
    "tool_touching",
    CONDITION,
    "True when the tool touches or overlaps the object.",
    _ONE,
    _TOLERANCE,
)
TOOL_NEAR_COLLISION = manifest(
    CAP,
    "tool_near_collision",
    CONDITION,
    "True when the tool is closer to the object than the distance (touching included).",
    _ONE,
    _DISTANCE,
)


class Contact:
    """``touching`` / ``near_collision`` between two objects, or the tool and an object."""

    def __init__(self, state: PredicatesState, port: str, tool: bool) -> None:
        self._state = state
        self._port = port  # "tolerance" (touching) or "distance" (near_collision)
        self._tool = tool
        self.start = _guarded(self._start)

    def _start(self, call: OperationCall) -> Job:
        state = self._state
        state.sample()
        limit: float = call.input(self._port)
        if self._tool:
            b = state.best(call.input("object"))
            first, second = (TOOL, state.tool_pose()), (b.object_class, b.pose)
            label = f"the tool and {b.object_class}"
        else:
            a, b = state.best(call.input("object_a")), state.best(call.input("object_b"))
            if a is b:
                raise PredicateError(f"object_a and object_b are both {a.object_class}")
            first, second = (a.object_class, a.pose), (b.object_class, b.pose)
            label = f"{a.object_class} and {b.object_class}"
        gap = state.collision().distance(first, second)
        gap_text = "over 1 m" if math.isinf(gap) else f"{gap * 1000:.1f} mm"
        word = "touching" if self._port == "tolerance" else "near collision"
        return _verdict(
            gap <= limit, f"{label}: {gap_text} apart ({word} at {limit * 1000:.1f} mm or less)"
        )


def setup(env: CapabilityEnv) -> PredicatesState:
    """The per-cell hook (``state.setup``), imported when a cell first needs it."""
    from capabilities.predicates import state

    return state.setup(env)


def capability() -> Capability:
    """The predicates capability; its per-cell state comes from ``state.setup``."""
    cap = Capability(
        CAP,
        "Predicates about objects: where they are relative to each other, motion, contact.",
        requires=("world", "objects"),
        settings=SETTINGS,
        setup=setup,
    )
    for relation, made in RELATIONS.items():
        cap.add(made, stateful(Relation, relation))
    cap.add(IS_MOVING, stateful(Moving, True))
    cap.add(IS_STATIONARY, stateful(Moving, False))
    cap.add(TOUCHING, stateful(Contact, "tolerance", False))
    cap.add(NEAR_COLLISION, stateful(Contact, "distance", False))
    cap.add(TOOL_TOUCHING, stateful(Contact, "tolerance", True))
    cap.add(TOOL_NEAR_COLLISION, stateful(Contact, "distance", True))
    return cap
