"""Marker geometry and OpenCV rotation vectors; the general helpers are capabilities.geometry's.

Quaternions are (x, y, z, w) as in :class:`engine.types.Pose`. Everything is numpy float64.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np
from numpy.typing import NDArray

from capabilities.geometry import (
    FloatArray,
    matrix_to_pose,
    matrix_to_quaternion,
    pose_errors,
    pose_to_matrix,
    quaternion_to_matrix,
    rotation_angle,
    transform_points,
)
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


def rotvec_to_matrix(rvec: Sequence[float] | NDArray[np.floating]) -> FloatArray:
    """The rotation matrix of a rotation vector (axis * angle in rad)."""
    r, _ = cv2.Rodrigues(np.asarray(rvec, dtype=np.float64).reshape(3, 1))
    return np.asarray(r, dtype=np.float64)


def matrix_to_rotvec(r: NDArray[np.floating]) -> FloatArray:
    """The rotation vector (axis * angle in rad) of a rotation matrix."""
    v, _ = cv2.Rodrigues(np.asarray(r, dtype=np.float64))
    return np.asarray(v, dtype=np.float64).reshape(3)


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


def marker_object_points(length: float) -> FloatArray:
    """The 4 corners (4x3, m) of a square marker in its own frame, in ArUco order.

    Order: top-left, top-right, bottom-right, bottom-left of the texture, which is the
    order ``cv2.aruco`` reports image corners in and ``SOLVEPNP_IPPE_SQUARE`` expects.
    The frame has x to the texture's right, y to its top, z out of the face.
    """
    h = float(length) / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])
