"""Poses at the UR edge: rotation vectors and the UR base frame.

The project's poses are position + quaternion (x, y, z, w) in the world frame. A UR controller
speaks ``[x, y, z, rx, ry, rz]`` (m, rotation vector in rad) in its base frame. These helpers
are the only place the two meet.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from capabilities.geometry import matrix_to_pose, pose_to_matrix, rotation_vector
from engine.types import Pose

__all__ = [
    "URFrames",
    "matrix_from_rotvec_pose",
    "rotvec_pose_from_matrix",
    "rotvec_to_matrix",
]


def rotvec_to_matrix(rv: Sequence[float]) -> np.ndarray:
    """The 3x3 rotation of a rotation vector (axis * angle, rad)."""
    v = np.asarray(rv, dtype=np.float64)
    angle = float(np.linalg.norm(v))
    if angle < 1e-12:
        return np.eye(3)
    k = v / angle
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.asarray(np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx)


def matrix_from_rotvec_pose(p: Sequence[float]) -> np.ndarray:
    """The 4x4 matrix of a UR pose ``[x, y, z, rx, ry, rz]``."""
    values = [float(v) for v in p]
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"a UR pose needs 6 finite numbers, got {values}")
    m = np.eye(4)
    m[:3, :3] = rotvec_to_matrix(values[3:])
    m[:3, 3] = values[:3]
    return m


def rotvec_pose_from_matrix(m: np.ndarray) -> list[float]:
    """The UR pose ``[x, y, z, rx, ry, rz]`` of a 4x4 matrix."""
    rv = rotation_vector(np.asarray(m)[:3, :3])
    t = np.asarray(m)[:3, 3]
    return [float(t[0]), float(t[1]), float(t[2]), float(rv[0]), float(rv[1]), float(rv[2])]


class URFrames:
    """World poses <-> UR base-frame rotation-vector poses.

    Args:
        base: the world pose of the UR base frame (the robot's mounting).
    """

    def __init__(self, base: Pose) -> None:
        self.base = base
        self._base = pose_to_matrix(base)
        self._base_inv = np.linalg.inv(self._base)

    def to_ur(self, pose: Pose) -> list[float]:
        """A world pose as the UR controller's ``[x, y, z, rx, ry, rz]`` in its base frame."""
        return rotvec_pose_from_matrix(self._base_inv @ pose_to_matrix(pose))

    def from_ur(self, p: Sequence[float]) -> Pose:
        """The world pose of a UR base-frame ``[x, y, z, rx, ry, rz]``."""
        return matrix_to_pose(self._base @ matrix_from_rotvec_pose(p))
