"""Small rigid-transform helpers between engine Poses, 4x4 matrices and OpenCV rotation vectors.

Quaternions are (x, y, z, w) as in :class:`engine.types.Pose`. Everything is numpy float64.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import cv2
import numpy as np
from numpy.typing import NDArray

from engine.types import Pose

__all__ = [
    "matrix_to_quaternion",
    "quaternion_to_matrix",
    "rotvec_to_matrix",
    "matrix_to_rotvec",
    "pose_to_matrix",
    "matrix_to_pose",
    "pose_from_rvec_tvec",
    "pose_to_rvec_tvec",
    "transform_points",
    "rotation_angle",
    "pose_errors",
    "marker_object_points",
]

FloatArray = NDArray[np.float64]


def quaternion_to_matrix(q: Sequence[float]) -> FloatArray:
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


def matrix_to_quaternion(r: NDArray[np.floating]) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation matrix, with w >= 0.

    The matrix is first projected onto the nearest rotation (SVD), so slightly
    non-orthogonal input from numerical work is fine.
    """
    u, _, vt = np.linalg.svd(np.asarray(r, dtype=np.float64))
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


def rotvec_to_matrix(rvec: Sequence[float] | NDArray[np.floating]) -> FloatArray:
    """The rotation matrix of a rotation vector (axis * angle in rad)."""
    r, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64).reshape(3, 1))
    return np.asarray(r, dtype=np.float64)


def matrix_to_rotvec(r: NDArray[np.floating]) -> FloatArray:
    """The rotation vector (axis * angle in rad) of a rotation matrix."""
    v, _ = cv2.Rodrigues(np.asarray(r, dtype=np.float64))
    return np.asarray(v, dtype=np.float64).reshape(3)


def pose_to_matrix(pose: Pose) -> FloatArray:
    """The 4x4 homogeneous matrix of a pose."""
    m = np.eye(4)
    m[:3, :3] = quaternion_to_matrix(pose.orientation)
    m[:3, 3] = pose.position
    return m


def matrix_to_pose(m: NDArray[np.floating]) -> Pose:
    """The pose of a 4x4 homogeneous matrix (or a 3x4 [R|t])."""
    arr = np.asarray(m, dtype=np.float64)
    t = arr[:3, 3]
    return Pose((float(t[0]), float(t[1]), float(t[2])), matrix_to_quaternion(arr[:3, :3]))


def pose_from_rvec_tvec(
    rvec: Sequence[float] | NDArray[np.floating], tvec: Sequence[float] | NDArray[np.floating]
) -> Pose:
    """The pose of an OpenCV (rvec, tvec) pair, i.e. the object's pose in the camera frame."""
    m = np.eye(4)
    m[:3, :3] = rotvec_to_matrix(rvec)
    m[:3, 3] = np.asarray(tvec, dtype=np.float64).reshape(3)
    return matrix_to_pose(m)


def pose_to_rvec_tvec(pose: Pose) -> tuple[FloatArray, FloatArray]:
    """The OpenCV (rvec, tvec) pair (each shape (3,)) of a pose."""
    m = pose_to_matrix(pose)
    return matrix_to_rotvec(m[:3, :3]), m[:3, 3].copy()


def transform_points(m: NDArray[np.floating], points: NDArray[np.floating]) -> FloatArray:
    """Apply a 4x4 transform to an (N, 3) array of points."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return np.asarray(pts @ m[:3, :3].T + m[:3, 3], dtype=np.float64)


def rotation_angle(r: NDArray[np.floating]) -> float:
    """The angle (rad) of a rotation matrix, in [0, pi]."""
    c = (float(np.trace(r)) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, c)))


def pose_errors(estimate: Pose, truth: Pose) -> tuple[float, float]:
    """Position error (m) and rotation error (rad) of ``estimate`` against ``truth``."""
    a, b = pose_to_matrix(estimate), pose_to_matrix(truth)
    dp = float(np.linalg.norm(a[:3, 3] - b[:3, 3]))
    return dp, rotation_angle(a[:3, :3].T @ b[:3, :3])


def marker_object_points(length: float) -> FloatArray:
    """The 4 corners (4x3, m) of a square marker in its own frame, in ArUco order.

    Order: top-left, top-right, bottom-right, bottom-left of the texture, which is the
    order ``cv2.aruco`` reports image corners in and ``SOLVEPNP_IPPE_SQUARE`` expects.
    The frame has x to the texture's right, y to its top, z out of the face.
    """
    h = float(length) / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])
