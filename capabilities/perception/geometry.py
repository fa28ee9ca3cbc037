"""Rigid transforms for perception: Pose <-> 4x4 matrices, the table frame, upright poses.

Objects rest on the table, so a recognised pose is (x, y, yaw) in a *table frame* whose
xy-plane is the fitted table plane; ``upright_pose`` turns that back into a world Pose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from engine.types import Pose

__all__ = [
    "matrix_to_pose",
    "pose_to_matrix",
    "table_frame",
    "upright_matrix",
    "wrap_angle",
    "yaw_of",
]


def pose_to_matrix(pose: Pose) -> np.ndarray:
    """The 4x4 homogeneous matrix of a pose."""
    x, y, z, w = pose.orientation
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = pose.position
    return m


def matrix_to_pose(m: np.ndarray) -> Pose:
    """The pose of a 4x4 matrix whose rotation part is orthonormal."""
    r = m[:3, :3]
    # Shepperd's method: take the largest of w, x, y, z first for numerical stability.
    t = np.trace(r)
    cases = [t, r[0, 0], r[1, 1], r[2, 2]]
    k = int(np.argmax(cases))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4)
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = (s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s)
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = ((r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = ((r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4, (r[1, 0] - r[0, 1]) / s)
    if q[3] < 0:
        q = (-q[0], -q[1], -q[2], -q[3])
    return Pose(tuple(float(v) for v in m[:3, 3]), q)  # type: ignore[arg-type]


def wrap_angle(angle: float) -> float:
    """The angle in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def yaw_of(rotation: np.ndarray) -> float:
    """The rotation about z that best matches a 3x3 rotation (its x axis seen from above)."""
    return math.atan2(rotation[1, 0], rotation[0, 0])


def upright_matrix(x: float, y: float, yaw: float, z: float = 0.0) -> np.ndarray:
    """4x4 of a pose turned ``yaw`` about z at (x, y, z)."""
    c, s = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = (x, y, z)
    return m


def table_frame(plane: Sequence[float] | np.ndarray) -> np.ndarray:
    """4x4 world <- table: z along the plane's upward normal, origin the world origin's
    projection onto the plane, x the world x axis projected onto the plane.

    Args:
        plane: (a, b, c, d) with a*x + b*y + c*z + d = 0 and (a, b, c) pointing up.
    """
    n = np.asarray(plane[:3], dtype=float)
    scale = float(np.linalg.norm(n))
    n, d = n / scale, float(plane[3]) / scale
    x = np.array([1.0, 0.0, 0.0]) - n[0] * n
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, :3] = np.column_stack((x, np.cross(n, x), n))
    m[:3, 3] = -d * n
    return m
