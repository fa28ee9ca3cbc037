"""Object symmetries in recognised poses: the canonical yaw, and a symmetry-aware error.

A cup (continuous symmetry about z) looks the same at every yaw; a plate with 4 holes at
every quarter turn. Recognition reports one *canonical* pose per object: the equivalent yaw
closest to a reference (the previous pose of a tracked object, else 0), so that the same
object gives the same pose from frame to frame.
"""

from __future__ import annotations

import math

import numpy as np

from capabilities.object_library import Symmetry
from capabilities.perception.geometry import pose_to_matrix, wrap_angle
from engine.types import Pose

__all__ = ["canonical_yaw", "pose_error", "rotation_error"]


def canonical_yaw(yaw: float, symmetry: Symmetry, reference: float = 0.0) -> float:
    """The yaw equivalent to ``yaw`` under a symmetry about z that is closest to ``reference``.

    Args:
        yaw: a recognised yaw (rad).
        symmetry: the model's symmetry (only symmetries about the z axis reduce the yaw).
        reference: the yaw to stay close to (rad).
    """
    if not _about_z(symmetry):
        return wrap_angle(yaw)
    if symmetry.kind == "continuous":
        return wrap_angle(reference)
    step = 2 * math.pi / max(1, symmetry.order)
    k = round((reference - yaw) / step)
    return wrap_angle(yaw + k * step)


def _about_z(symmetry: Symmetry) -> bool:
    axis = np.asarray(symmetry.axis, dtype=float)
    return symmetry.kind != "none" and abs(axis[2]) / np.linalg.norm(axis) > 0.999


def _angle(r: np.ndarray) -> float:
    return math.acos(max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0)))


def rotation_error(estimate: Pose, truth: Pose, symmetry: Symmetry) -> float:
    """The smallest rotation (rad) between two poses of an object, given its symmetry.

    Continuous symmetry: the angle between the symmetry axes (any turn about it is right);
    discrete: the smallest angle over the equivalent rotations; none: the plain angle.
    """
    r_est = pose_to_matrix(estimate)[:3, :3]
    r_true = pose_to_matrix(truth)[:3, :3]
    axis = np.asarray(symmetry.axis, dtype=float)
    axis /= np.linalg.norm(axis)
    if symmetry.kind == "continuous":
        cos = float(np.dot(r_est @ axis, r_true @ axis))
        return math.acos(max(-1.0, min(1.0, cos)))
    angles = symmetry.angles() or (0.0,)
    best = math.pi
    for angle in angles:
        best = min(best, _angle(r_est.T @ r_true @ _axis_rotation(axis, angle)))
    return best


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def pose_error(estimate: Pose, truth: Pose, symmetry: Symmetry) -> tuple[float, float]:
    """(position error in m, symmetry-aware rotation error in rad)."""
    return math.dist(estimate.position, truth.position), rotation_error(estimate, truth, symmetry)
