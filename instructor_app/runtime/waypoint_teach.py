"""Teaching a waypoint where the arm is now (no Qt: the panels and the inspector use it).

A waypoint is taught as the joints, the tool pose in the world, or the tool pose relative to
an object or a marker the cell has recognised (the paper's Figure 6: the pick pose of a
plate, taught once relative to the plate, follows the plate wherever it is detected). The
reference comes from the cell's world model, that is from perception, never from a
simulator's ground truth; without a name given, the recognised object (or marker) nearest
to the tool is used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from engine.types import JointConfig, Pose, Waypoint, WaypointFrame
from instructor_app.errors import InstructorError

__all__ = ["TeachError", "nearest_reference", "teach_waypoint", "teach_like"]


class TeachError(InstructorError):
    """A waypoint cannot be taught now; the message says what is missing."""


def _distance(a: Pose, b: Pose) -> float:
    return math.dist(a.position, b.position)


def nearest_reference(world: Any, frame: WaypointFrame, tool: Pose) -> tuple[str, Pose]:
    """(reference, its pose) of the recognised object or seen marker nearest the tool."""
    found: list[tuple[str, Pose]] = []
    if frame is WaypointFrame.OBJECT and world is not None and hasattr(world, "detections"):
        found = [(d.object_class, d.pose) for d in world.detections()]
    elif frame is WaypointFrame.MARKER and world is not None and hasattr(world, "markers"):
        found = [(str(marker_id), pose) for marker_id, (pose, _) in world.markers().items()]
    if not found:
        what = "object" if frame is WaypointFrame.OBJECT else "marker"
        raise TeachError(f"the cell has not recognised any {what}: detect first")
    return min(found, key=lambda item: _distance(item[1], tool))


def _reference_pose(world: Any, frame: WaypointFrame, reference: str) -> Pose:
    if world is None:
        raise TeachError("this cell has no world model to find the reference in")
    if frame is WaypointFrame.MARKER:
        try:
            seen = world.marker(int(reference))
        except ValueError:
            raise TeachError(f"marker reference {reference!r} is not a marker id") from None
        if seen is None:
            raise TeachError(f"marker {reference} has not been seen: detect markers first")
        return seen[0]
    detection = world.best(reference)
    if detection is None:
        raise TeachError(f"the cell has not recognised {reference!r}: detect it first")
    return detection.pose


def teach_waypoint(
    interfaces: Mapping[str, Any], name: str, frame: WaypointFrame, reference: str = ""
) -> Waypoint:
    """A waypoint where the arm is now.

    Args:
        interfaces: the cell's interfaces (``arm``; ``world`` for relative frames).
        name: the waypoint's name.
        frame: joints, world, object or marker.
        reference: the object class or marker id; "" for the nearest one recognised.

    Raises:
        TeachError: no name, no arm, or no reference recognised.
    """
    name = name.strip()
    if not name:
        raise TeachError("type a name for the waypoint first")
    arm = interfaces.get("arm")
    if arm is None:
        raise TeachError("this cell has no arm to record from")
    if frame is WaypointFrame.JOINTS:
        return Waypoint(name, frame, joints=JointConfig(tuple(arm.joint_positions())))
    tool = arm.tcp_pose()
    if frame is WaypointFrame.WORLD:
        return Waypoint(name, frame, pose=tool)
    world = interfaces.get("world")
    reference = reference.strip()
    if reference:
        seen = _reference_pose(world, frame, reference)
    else:
        reference, seen = nearest_reference(world, frame, tool)
    return Waypoint(name, frame, pose=seen.inverse().compose(tool), reference=reference)


def teach_like(interfaces: Mapping[str, Any], waypoint: Waypoint) -> Waypoint:
    """``waypoint`` taught again where the arm is now, in its own frame and reference."""
    return teach_waypoint(interfaces, waypoint.name, waypoint.frame, waypoint.reference)
