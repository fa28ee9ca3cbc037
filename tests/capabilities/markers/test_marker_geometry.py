"""Rotation helpers: quaternion, matrix and rotation-vector round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from capabilities.markers.geometry import (
    matrix_to_pose,
    matrix_to_quaternion,
    pose_errors,
    pose_from_rvec_tvec,
    pose_to_matrix,
    pose_to_rvec_tvec,
    quaternion_to_matrix,
    rotvec_to_matrix,
)
from engine.types import Pose


def test_quaternion_matrix_round_trip_over_random_rotations() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        back = np.array(matrix_to_quaternion(quaternion_to_matrix(q)))
        assert min(np.linalg.norm(back - q), np.linalg.norm(back + q)) < 1e-9


def test_matrix_matches_pose_compose() -> None:
    a = Pose((0.1, -0.2, 0.3), (0.1, 0.2, 0.3, 0.9))
    b = Pose((0.4, 0.0, -0.1), (-0.3, 0.1, 0.5, 0.7))
    expected = pose_to_matrix(a) @ pose_to_matrix(b)
    assert np.allclose(pose_to_matrix(a.compose(b)), expected, atol=1e-12)
    assert np.allclose(pose_to_matrix(a.inverse()), np.linalg.inv(pose_to_matrix(a)), atol=1e-12)


def test_rotvec_round_trip_and_known_rotation() -> None:
    r = rotvec_to_matrix([0.0, 0.0, math.pi / 2])
    assert np.allclose(r @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-12)
    pose = Pose((1.0, 2.0, 3.0), (0.2, -0.1, 0.4, 0.8))
    rvec, tvec = pose_to_rvec_tvec(pose)
    dp, dr = pose_errors(pose_from_rvec_tvec(rvec, tvec), pose)
    assert dp < 1e-12 and dr < 1e-7


def test_matrix_to_quaternion_rejects_reflection() -> None:
    with pytest.raises(ValueError):
        matrix_to_quaternion(np.diag([1.0, 1.0, -1.0]))


def test_matrix_to_pose_reads_translation() -> None:
    m = np.eye(4)
    m[:3, 3] = (0.5, 0.25, -1.0)
    assert matrix_to_pose(m).position == (0.5, 0.25, -1.0)
