"""Turning a move_to target (a Pose or a Waypoint) into tool poses in the world frame.

A waypoint taught relative to an object stores the tool pose in the object's frame (the
paper's smart waypoint). At run time it is composed with the object's pose: the one bound to
the operation, or the world model's best detection of the waypoint's class. Symmetric
objects give several equivalent tool poses; they are ordered by how little the wrist has to
turn from where the tool is now, and the first reachable one is used.

A Pose target with a Pose reference is taken in the reference's frame (``reference *
target``); a reference with a waypoint in the world or joints frame is an error, never
ignored. A Pose target with a grasp reference (``"cup"`` or ``"cup/rim"``) is an object's pose, as
Figure 3's "move to CUP_POSE": the tool goes to that grasp of the object's model, through
the grasp's approach (:class:`capabilities.object_library.GraspSpec`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from capabilities.motion.backend import WorldBackend
from capabilities.motion.geometry import axis_rotation, format_pose_mm, rotation_between
from capabilities.motion.symmetry import ObjectSymmetry, SymmetryTable
from capabilities.object_library import ObjectLibraryError
from engine.operations import OperationFailed
from engine.types import JointConfig, Pose, Waypoint, WaypointFrame

__all__ = [
    "ResolvedTarget",
    "TargetResolver",
    "reference_set",
    "symmetric_rotations",
    "symmetric_tool_poses",
    "unused_reference",
]

_CONTINUOUS_STEPS = 24  # fallbacks tried around a continuous symmetry, 15 deg apart


@dataclass(frozen=True)
class ResolvedTarget:
    """Where to go: candidate tool poses (best first) or joints, and words for messages.

    ``approaches``, when given, has one pose per candidate: the tool gets there first (a
    joint move) and goes on to the candidate in a straight line (a grasp's approach).
    """

    describe: str
    poses: tuple[Pose, ...] = ()
    joints: JointConfig | None = None
    approaches: tuple[Pose, ...] = ()


def symmetric_rotations(
    object_pose: Pose, tool_in_object: Pose, symmetry: ObjectSymmetry, current: Pose
) -> list[Pose]:
    """The object's symmetry rotations (object frame) that bring ``tool_in_object`` nearest
    the tool's ``current`` orientation first: turn any pose taught relative to the object by
    one of them and the object looks the same to it.

    For a continuous symmetry the best angle is found in closed form: with
    m = q_obj^-1 * q_now * q_tool^-1, the rotation r(t) about axis a that maximises
    |<q_now, q_obj r(t) q_tool>| = |(m_v . a) sin(t/2) + m_w cos(t/2)| is t = 2 atan2(m_v . a, m_w).
    """
    angles: tuple[float, ...]
    if symmetry.angles is None:
        m = object_pose.inverse().compose(current).compose(tool_in_object.inverse()).orientation
        along = sum(m[i] * symmetry.axis[i] for i in range(3))
        best = 2 * math.atan2(along, m[3])
        angles = tuple(best + 2 * math.pi * k / _CONTINUOUS_STEPS for k in range(_CONTINUOUS_STEPS))
    else:
        angles = symmetry.angles or (0.0,)
    rotations = [axis_rotation(symmetry.axis, angle) for angle in angles]

    def turn(rotation: Pose) -> float:
        return rotation_between(current, object_pose.compose(rotation).compose(tool_in_object))

    return sorted(rotations, key=turn)


def symmetric_tool_poses(
    object_pose: Pose, tool_in_object: Pose, symmetry: ObjectSymmetry, current: Pose
) -> list[Pose]:
    """The tool poses equivalent under the object's symmetry, least wrist rotation first."""
    return [
        object_pose.compose(rotation).compose(tool_in_object)
        for rotation in symmetric_rotations(object_pose, tool_in_object, symmetry, current)
    ]


def reference_set(reference: Any) -> bool:
    """True when move_to's ``reference`` says something (a pose, or a non-empty text)."""
    return reference is not None and not (isinstance(reference, str) and not reference.strip())


def unused_reference(target: Waypoint) -> str:
    """Why a reference cannot go with a waypoint in the world or joints frame."""
    frame = "joint positions" if target.frame is WaypointFrame.JOINTS else "in the world frame"
    return (
        f"'reference' is set, but the waypoint {target.name!r} is {frame}, not relative to an "
        "object or a marker, so the reference would be ignored: clear 'reference', or teach "
        "the waypoint relative to the object"
    )


class TargetResolver:
    """Resolves move_to targets against the world model and the object symmetries.

    Args:
        world: the cell's world model, or None when the cell has none.
        symmetries: object class -> symmetry.
    """

    def __init__(self, world: WorldBackend | None, symmetries: SymmetryTable) -> None:
        self._world = world
        self._symmetries = symmetries

    def resolve(self, target: Any, reference: Any, current: Pose) -> ResolvedTarget:
        """Candidate poses for ``target``; raises OperationFailed saying what is missing."""
        if isinstance(target, Pose) and isinstance(reference, str) and reference.strip():
            return self._grasp(target, reference.strip(), current)
        if isinstance(target, Pose) and isinstance(reference, Pose):
            return ResolvedTarget(
                f"pose {format_pose_mm(target)} relative to the reference at "
                f"{format_pose_mm(reference)}",
                (reference.compose(target),),
            )
        if isinstance(target, Pose):
            return ResolvedTarget(f"pose {format_pose_mm(target)}", (target,))
        if not isinstance(target, Waypoint):
            raise OperationFailed(
                f"the target must be a Pose or a Waypoint, not {type(target).__name__}"
            )
        if target.frame in (WaypointFrame.JOINTS, WaypointFrame.WORLD) and reference_set(reference):
            raise OperationFailed(unused_reference(target))
        if target.frame is WaypointFrame.JOINTS:
            return ResolvedTarget(f"waypoint {target.name!r} (joints)", joints=target.joints)
        assert target.pose is not None  # Waypoint checks this for non-joint frames
        if target.frame is WaypointFrame.WORLD:
            return ResolvedTarget(f"waypoint {target.name!r}", (target.pose,))
        if target.frame is WaypointFrame.MARKER:
            marker_pose = self._marker_pose(target, reference)
            return ResolvedTarget(
                f"waypoint {target.name!r} relative to marker {target.reference}",
                (marker_pose.compose(target.pose),),
            )
        object_class = reference if isinstance(reference, str) and reference else target.reference
        object_pose = reference if isinstance(reference, Pose) else self._detected(object_class)
        symmetry, _note = self._symmetries.lookup(object_class)
        poses = symmetric_tool_poses(object_pose, target.pose, symmetry, current)
        return ResolvedTarget(
            f"waypoint {target.name!r} relative to {object_class} at {format_pose_mm(object_pose)}",
            tuple(poses),
        )

    def _grasp(self, object_pose: Pose, reference: str, current: Pose) -> ResolvedTarget:
        """A grasp reference ``model`` or ``model/grasp`` on the object at ``object_pose``."""
        object_class, _, name = reference.partition("/")
        try:
            grasp = self._symmetries.grasp(object_class, name)
        except (ObjectLibraryError, OSError) as exc:
            raise OperationFailed(f"grasp reference {reference!r}: {exc}") from exc
        symmetry, _note = self._symmetries.lookup(object_class)
        turned = [
            object_pose.compose(rotation)
            for rotation in symmetric_rotations(object_pose, grasp.pose, symmetry, current)
        ]
        return ResolvedTarget(
            f"grasp {grasp.name!r} of the {object_class} at {format_pose_mm(object_pose)}",
            tuple(t.compose(grasp.pose) for t in turned),
            approaches=tuple(t.compose(grasp.approach) for t in turned),
        )

    def _detected(self, object_class: str) -> Pose:
        if self._world is None:
            raise OperationFailed(
                f"this cell has no world model: bind 'reference' to the pose of the {object_class}"
            )
        detection = self._world.best(object_class)
        if detection is None:
            raise OperationFailed(
                f"no {object_class!r} has been detected: run a perception operation first, "
                "or bind 'reference' to its pose"
            )
        return detection.pose

    def _marker_pose(self, target: Waypoint, reference: Any) -> Pose:
        if isinstance(reference, Pose):
            return reference
        text = reference if isinstance(reference, str) and reference else target.reference
        try:
            marker_id = int(text)
        except ValueError as exc:
            raise OperationFailed(f"marker reference {text!r} is not a marker id") from exc
        if self._world is None:
            raise OperationFailed("this cell has no world model to look up marker poses in")
        seen = self._world.marker(marker_id)
        if seen is None:
            raise OperationFailed(f"marker {marker_id} has not been seen: detect markers first")
        return seen[0]
