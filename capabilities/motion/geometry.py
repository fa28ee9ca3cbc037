"""Small pose helpers of the motion capability (pure Python on engine.types.Pose).

Kept here rather than borrowed from the simulated cell so that motion runs on any cell.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from engine.types import Pose
from engine.units import quaternion_to_rpy

__all__ = [
    "axis_rotation",
    "format_pose_mm",
    "rotation_between",
    "translated",
    "quaternion_dot",
]


def axis_rotation(axis: Sequence[float], angle: float) -> Pose:
    """A pure rotation of ``angle`` rad about the unit vector ``axis``."""
    norm = math.sqrt(sum(v * v for v in axis)) or 1.0
    s = math.sin(angle / 2) / norm
    return Pose((0.0, 0.0, 0.0), (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2)))


def quaternion_dot(a: Pose, b: Pose) -> float:
    """The dot product of two poses' unit quaternions (1 or -1: same orientation)."""
    return sum(x * y for x, y in zip(a.orientation, b.orientation, strict=True))


def rotation_between(a: Pose, b: Pose) -> float:
    """The angle (rad, 0..pi) of the rotation that turns orientation ``a`` into ``b``."""
    return 2 * math.acos(min(1.0, abs(quaternion_dot(a, b))))


def translated(pose: Pose, dx: float, dy: float, dz: float) -> Pose:
    """``pose`` moved by (dx, dy, dz) m in the world frame, orientation kept."""
    x, y, z = pose.position
    return Pose((x + dx, y + dy, z + dz), pose.orientation)


def format_pose_mm(pose: Pose) -> str:
    """A pose as users read it: position in mm, orientation as roll/pitch/yaw in degrees."""
    x, y, z = (v * 1000 for v in pose.position)
    roll, pitch, yaw = (math.degrees(v) for v in quaternion_to_rpy(pose.orientation))
    return (
        f"({x:.1f}, {y:.1f}, {z:.1f}) mm, roll/pitch/yaw ({roll:.1f}, {pitch:.1f}, {yaw:.1f}) deg"
    )
