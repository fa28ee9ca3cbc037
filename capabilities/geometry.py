"""Rigid-transform helpers shared by the capabilities: Pose <-> 4x4 matrix, quaternions,
rotation angles and vectors. Quaternions are (x, y, z, w) as in :class:`engine.types.Pose`;
matrices are numpy float64.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from engine.types import Pose

__all__ = [
    "FloatArray",
    "matrix_to_pose",
    "matrix_to_quaternion",
    "pose_errors",
    "pose_to_matrix",
    "quaternion_to_matrix",
    "rotation_angle",
    "rotation_vector",
    "transform_points",
]

FloatArray = NDArray[np.float64]


def quaternion_to_matrix(q: Sequence[float] | NDArray[np.floating]) -> FloatArray:
    """The 3x3 rotation matrix of a quaternion (x, y, z, w); it need not be normalised."""
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quaternion(
    r: NDArray[np.floating], project: bool = True
) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation matrix, with w >= 0.

    Args:
        r: a 3x3 rotation matrix.
        project: first project onto the nearest rotation (SVD), for slightly non-orthogonal
            matrices from numerical work; the controllers, which call this every physics
            step with exact rotations, skip it.
    """
    m = np.asarray(r, dtype=np.float64)
    if project:
        u, _, vt = np.linalg.svd(m)
        m = u @ vt
        if np.linalg.det(m) < 0:
            raise ValueError("matrix is a reflection, not a rotation")
    # Shepperd's method: branch on the largest diagonal term for numerical stability.
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s)
    sign = -1.0 if q[3] < 0 else 1.0
    norm = math.sqrt(sum(v * v for v in q))
    return (sign * q[0] / norm, sign * q[1] / norm, sign * q[2] / norm, sign * q[3] / norm)


def pose_to_matrix(pose: Pose) -> FloatArray:
    """The 4x4 homogeneous matrix of a pose."""
    m = np.eye(4)
    m[:3, :3] = quaternion_to_matrix(pose.orientation)
    m[:3, 3] = pose.position
    return m


def matrix_to_pose(m: NDArray[np.floating], project: bool = True) -> Pose:
    """The pose of a 4x4 homogeneous matrix (or a 3x4 [R|t])."""
    arr = np.asarray(m, dtype=np.float64)
    t = arr[:3, 3]
    rotation = matrix_to_quaternion(arr[:3, :3], project)
    return Pose((float(t[0]), float(t[1]), float(t[2])), rotation)


def transform_points(m: NDArray[np.floating], points: NDArray[np.floating]) -> FloatArray:
    """Apply a 4x4 transform to an (N, 3) array of points."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return np.asarray(pts @ m[:3, :3].T + m[:3, 3], dtype=np.float64)


def rotation_angle(r: NDArray[np.floating]) -> float:
    """The angle (rad) of a rotation matrix, in [0, pi]."""
    c = (float(np.trace(r)) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, c)))


def rotation_vector(r: NDArray[np.floating]) -> FloatArray:
    """Axis * angle (rad) of a 3x3 rotation matrix."""
    angle = rotation_angle(r)
    if angle < 1e-9:
        return np.zeros(3)
    axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]], dtype=np.float64)
    norm = np.linalg.norm(axis)
    if norm < 1e-9:  # angle near pi: take the axis from the symmetric part
        sym = (np.asarray(r, dtype=np.float64) + np.eye(3)) / 2.0
        axis = sym[:, int(np.argmax(np.diag(sym)))]
        norm = np.linalg.norm(axis)
    return np.asarray(axis / norm * angle, dtype=np.float64)


def pose_errors(estimate: Pose, truth: Pose) -> tuple[float, float]:
    """Position error (m) and rotation error (rad) of ``estimate`` against ``truth``."""
    a, b = pose_to_matrix(estimate), pose_to_matrix(truth)
    dp = float(np.linalg.norm(a[:3, 3] - b[:3, 3]))
    return dp, rotation_angle(a[:3, :3].T @ b[:3, :3])
