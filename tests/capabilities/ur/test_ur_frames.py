"""UR rotation-vector poses and the UR base frame (capabilities.ur.frames)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from capabilities.geometry import pose_errors
from capabilities.ur.frames import URFrames, matrix_from_rotvec_pose, rotvec_to_matrix
from engine.types import Pose


@pytest.mark.parametrize(
    "rv",
    [(0.0, 0.0, 0.0), (0.3, -0.2, 0.1), (0.0, math.pi, 0.0), (2.2, 2.2, 0.0), (0, 0, -3.0)],
)
def test_rotation_vector_round_trip_through_world_poses(rv: tuple[float, float, float]) -> None:
    base = Pose((0.1, -0.2, 0.8), (0.0, 0.0, 1.0, 0.0))  # turned 180 degrees about z
    frames = URFrames(base)
    ur_pose = [0.4, -0.1, 0.3, *rv]
    world = frames.from_ur(ur_pose)
    back = frames.to_ur(world)
    assert np.allclose(matrix_from_rotvec_pose(back), matrix_from_rotvec_pose(ur_pose), atol=1e-9)
    position, angle = pose_errors(frames.from_ur(back), world)
    assert position < 1e-9 and angle < 1e-6


def test_base_frame_is_applied() -> None:
    frames = URFrames(Pose((1.0, 2.0, 0.5), (0.0, 0.0, 1.0, 0.0)))
    world = frames.from_ur([0.2, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert world.position == pytest.approx((0.8, 2.0, 0.5))


def test_rotvec_matches_axis_angle() -> None:
    r = rotvec_to_matrix((0.0, 0.0, math.pi / 2))
    assert r @ np.array([1.0, 0.0, 0.0]) == pytest.approx([0.0, 1.0, 0.0])


def test_bad_ur_pose_is_refused() -> None:
    with pytest.raises(ValueError, match="6 finite numbers"):
        matrix_from_rotvec_pose([0.0, 0.0, float("nan"), 0.0, 0.0, 0.0])
