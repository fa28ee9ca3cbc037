"""Small rigid-transform helpers: Pose <-> 4x4 matrix, quaternions, slerp, rotation error.

numpy matrices are used inside the controllers (they run every physics step); ``Pose`` from
``engine.types`` is what crosses the API.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from engine.types import Pose

__all__ = [
    "pose_to_matrix",
    "matrix_to_pose",
    "quat_to_matrix",
    "matrix_to_quat",
    "slerp",
    "rotation_angle",
    "rotation_vector",
    "pose_text_mm",
]


def quat_to_matrix(q: Sequence[float] | np.ndarray) -> np.ndarray:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(r: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (x, y, z, w) of a 3x3 rotation matrix (Shepperd's method), w >= 0."""
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4)
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = (s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s)
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = ((r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = ((r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4, (r[1, 0] - r[0, 1]) / s)
    if q[3] < 0:
        q = (-q[0], -q[1], -q[2], -q[3])
    norm = math.sqrt(sum(v * v for v in q))
    return (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm)


def pose_to_matrix(pose: Pose) -> np.ndarray:
    """4x4 homogeneous matrix of a pose."""
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(pose.orientation)
    m[:3, 3] = pose.position
    return m


def matrix_to_pose(m: np.ndarray) -> Pose:
    """Pose of a 4x4 homogeneous matrix."""
    return Pose(tuple(float(v) for v in m[:3, 3]), matrix_to_quat(m[:3, :3]))  # type: ignore[arg-type]


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """Axis * angle (rad) of a 3x3 rotation matrix."""
    angle = rotation_angle(r)
    if angle < 1e-9:
        return np.zeros(3)
    axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    norm = np.linalg.norm(axis)
    if norm < 1e-9:  # angle near pi: take the axis from the symmetric part
        sym = (r + np.eye(3)) / 2.0
        axis = sym[:, int(np.argmax(np.diag(sym)))]
        norm = np.linalg.norm(axis)
    return axis / norm * angle


def rotation_angle(r: np.ndarray) -> float:
    """Angle (rad, 0..pi) of a 3x3 rotation matrix."""
    return math.acos(max(-1.0, min(1.0, (float(np.trace(r)) - 1.0) / 2.0)))


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
