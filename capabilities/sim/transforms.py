"""Small rigid-transform helpers: Pose <-> 4x4 matrix, quaternions, slerp, rotation error.

numpy matrices are used inside the controllers (they run every physics step); ``Pose`` from
``engine.types`` is what crosses the API.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from capabilities.geometry import matrix_to_pose as _matrix_to_pose
from capabilities.geometry import (
    matrix_to_quaternion,
    pose_to_matrix,
    quaternion_to_matrix,
    rotation_angle,
    rotation_vector,
)
from engine.types import Pose

__all__ = [
    "matrix_to_pose",
    "matrix_to_quat",
    "pose_text_mm",
    "pose_to_matrix",
    "quat_to_matrix",
    "rotation_angle",
    "rotation_vector",
    "slerp",
]


# The controllers convert exact rotations every physics step: no SVD projection there.
quat_to_matrix = quaternion_to_matrix


def matrix_to_quat(r: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of an exact 3x3 rotation matrix, w >= 0."""
    return matrix_to_quaternion(r, project=False)


def matrix_to_pose(m: np.ndarray) -> Pose:
    """Pose of an exact 4x4 homogeneous matrix."""
    return _matrix_to_pose(m, project=False)


def slerp(q0: Sequence[float], q1: Sequence[float], u: float) -> np.ndarray:
    """Spherical interpolation of unit quaternions (x, y, z, w), shortest arc, u in [0, 1]."""
    a = np.asarray(q0, dtype=float)
    b = np.asarray(q1, dtype=float)
    dot = float(np.dot(a, b))
    if dot < 0:
        b, dot = -b, -dot
    if dot > 0.9995:
        out = a + u * (b - a)
        return out / np.linalg.norm(out)
    theta = math.acos(dot)
    return (math.sin((1 - u) * theta) * a + math.sin(u * theta) * b) / math.sin(theta)


def pose_text_mm(pose: Pose) -> str:
    """A pose for messages: position in mm, orientation as quaternion."""
    x, y, z = (v * 1000.0 for v in pose.position)
    q = ", ".join(f"{v:.3f}" for v in pose.orientation)
    return f"({x:.1f}, {y:.1f}, {z:.1f}) mm, q=({q})"
