"""Operations of the predicates capability (the paper's Predicator), all conditions.

Object poses are the world model's best detections (filled by the markers or perception
capabilities); the tool is a box at the arm's TCP pose. Every predicate answers at once
(no camera, no blocking) with a finished Job whose message says why it holds or not.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, ClassVar

from capabilities.base import Capability, CapabilityEnv, OperationClass
from capabilities.kit import (
    InPort,
    OperationKind,
    StatefulOperation,
    duration,
    manifest,
    number,
    object_model,
    text,
    variant,
)
from capabilities.predicates.collision import TOOL, PredicateError
from capabilities.predicates.settings import DIRECTIONS, SETTINGS
from engine.operations import Job, OperationCall, OperationFailed, StartResult
from engine.types import ObjectModel, Pose

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


class _Predicate(StatefulOperation["PredicatesState"]):
    """A predicate over the per-cell state; a PredicateError fails the node with its text."""

    def start(self, call: OperationCall) -> StartResult:
        try:
            return self._start(call)
        except PredicateError as exc:
            raise OperationFailed(str(exc)) from exc

    def _start(self, call: OperationCall) -> Job:
        raise NotImplementedError


OBJECT_A = object_model("object_a", doc="the object the predicate is about")
OBJECT_B = object_model("object_b", doc="the object it is compared with")
OBJECT = object_model("object", doc="the object")
FRAME = text(
    "frame",
    "world",
    choices=FRAMES,
    doc="directions along the world's, the robot base's or object_b's axes",
)
MARGIN = number(
    "margin", 0.01, unit="m", doc="by more than this (a tie under sensor noise is neither)"
)


class _Relation(_Predicate):
    """``left_of``, ``right_of``, ``in_front_of``, ``behind``, ``up_from``, ``down_from``."""

    RELATION: ClassVar[str]

    @classmethod
    def of(cls, relation: str) -> OperationClass:
        """The operation ``relation`` (a key of ``DIRECTIONS``)."""
        doc = (
            f"True when object_a is {relation.replace('_', ' ')} object_b (centres, "
            "along the frame's axes: front +x, left +y, up +z)."
        )
        ports = (OBJECT_A, OBJECT_B, FRAME, MARGIN)
        return variant(cls, manifest(CAP, relation, CONDITION, doc, *ports), RELATION=relation)

    def _start(self, call: OperationCall) -> Job:
        from capabilities.predicates.geometry import box_center, offset_in_frame

        state = self._state
        state.sample()
        a, b = state.best(call.input(OBJECT_A)), state.best(call.input(OBJECT_B))
        frame_name = call.input(FRAME)
        frame = self._frame(frame_name, b.pose)
        margin = call.input(MARGIN)
        offset = offset_in_frame(
            box_center(a.pose, state.height(a.object_class)),
            box_center(b.pose, state.height(b.object_class)),
            frame,
        )
        axis, sign = DIRECTIONS[self.RELATION]
        along = sign * float(offset[axis])
        words = self.RELATION.replace("_", " ")
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


RELATIONS = tuple(_Relation.of(relation) for relation in DIRECTIONS)
"""``left_of``, ``right_of``, ``in_front_of``, ``behind``, ``up_from``, ``down_from``."""


WINDOW = duration("window", 0.5, doc="judge the detections of this last stretch of time")
SPEED = number("speed", 0.02, unit="m/s", doc="faster than this is moving")


class _Moving(_Predicate):
    """``is_moving`` (WANT True) or ``is_stationary`` (WANT False) over a time window."""

    WANT: ClassVar[bool]

    @classmethod
    def of(cls, name: str, want: bool, doc: str) -> OperationClass:
        """The operation ``name``, true when the object moves (``want``) or stays."""
        return variant(cls, manifest(CAP, name, CONDITION, doc, OBJECT, WINDOW, SPEED), WANT=want)

    def _start(self, call: OperationCall) -> Job:
        state = self._state
        state.sample()
        name = _name(call.input(OBJECT))
        window = call.input(WINDOW)
        threshold = call.input(SPEED)
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
        return _verdict(moving == self.WANT, text)


IsMoving = _Moving.of(
    "is_moving", True, "True when the object's detections moved faster than the speed."
)
IsStationary = _Moving.of(
    "is_stationary",
    False,
    "True when the object's detections stayed (slower than the speed); "
    "false when too few were seen.",
)


TOLERANCE = number("tolerance", 0.003, unit="m", doc="surfaces this close count as touching")
DISTANCE = number("distance", 0.03, unit="m", doc="surfaces this close are a near collision")


class _Contact(_Predicate):
    """``touching`` / ``near_collision`` between two objects, or the tool and an object."""

    LIMIT: ClassVar[InPort[float]]  # TOLERANCE (touching) or DISTANCE (near_collision)
    TOOL: ClassVar[bool]

    @classmethod
    def of(cls, name: str, doc: str) -> OperationClass:
        """The operation ``name``: ``[tool_]touching`` or ``[tool_]near_collision``."""
        limit = DISTANCE if name.endswith("near_collision") else TOLERANCE
        tool = name.startswith("tool_")
        ports = (OBJECT, limit) if tool else (OBJECT_A, OBJECT_B, limit)
        return variant(cls, manifest(CAP, name, CONDITION, doc, *ports), LIMIT=limit, TOOL=tool)

    def _start(self, call: OperationCall) -> Job:
        state = self._state
        state.sample()
        limit = call.input(self.LIMIT)
        if self.TOOL:
            b = state.best(call.input(OBJECT))
            first, second = (TOOL, state.tool_pose()), (b.object_class, b.pose)
            label = f"the tool and {b.object_class}"
        else:
            a, b = state.best(call.input(OBJECT_A)), state.best(call.input(OBJECT_B))
            if a is b:
                raise PredicateError(f"object_a and object_b are both {a.object_class}")
            first, second = (a.object_class, a.pose), (b.object_class, b.pose)
            label = f"{a.object_class} and {b.object_class}"
        gap = state.collision().distance(first, second)
        gap_text = "over 1 m" if math.isinf(gap) else f"{gap * 1000:.1f} mm"
        word = "touching" if self.LIMIT is TOLERANCE else "near collision"
        return _verdict(
            gap <= limit, f"{label}: {gap_text} apart ({word} at {limit * 1000:.1f} mm or less)"
        )


Touching = _Contact.of("touching", "True when the two objects' shapes touch or overlap.")
NearCollision = _Contact.of(
    "near_collision",
    "True when the two objects' shapes are closer than the distance (touching included).",
)
ToolTouching = _Contact.of("tool_touching", "True when the tool touches or overlaps the object.")
ToolNearCollision = _Contact.of(
    "tool_near_collision",
    "True when the tool is closer to the object than the distance (touching included).",
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
    cap.add(
        *RELATIONS,
        IsMoving,
        IsStationary,
        Touching,
        NearCollision,
        ToolTouching,
        ToolNearCollision,
    )
    return cap
