"""Rigid transforms for perception: Pose <-> 4x4 matrices, the table frame, upright poses.

Objects rest on the table, so a recognised pose is (x, y, yaw) in a *table frame* whose
xy-plane is the fitted table plane; ``upright_pose`` turns that back into a world Pose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from capabilities.geometry import matrix_to_pose as _matrix_to_pose
from capabilities.geometry import pose_to_matrix
from engine.types import Pose

__all__ = [
    "matrix_to_pose",
    "pose_to_matrix",
    "table_frame",
    "upright_matrix",
    "wrap_angle",
    "yaw_of",
]


def matrix_to_pose(m: np.ndarray) -> Pose:
    """The pose of a 4x4 matrix whose rotation part is orthonormal."""
    return _matrix_to_pose(m, project=False)


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
