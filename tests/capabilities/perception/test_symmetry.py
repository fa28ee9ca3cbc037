"""Canonical yaws and symmetry-aware pose errors."""

from __future__ import annotations

import math

import pytest

from capabilities.object_library import Symmetry
from capabilities.perception.geometry import (
    matrix_to_pose,
    pose_to_matrix,
    table_frame,
    upright_matrix,
)
from capabilities.perception.symmetry import canonical_yaw, pose_error, rotation_error
from engine.types import Pose

CONTINUOUS = Symmetry("continuous")
HALF_TURN = Symmetry("discrete", order=2)
QUARTER_TURN = Symmetry("discrete", order=4)


def _yaw(angle: float, x: float = 0.0) -> Pose:
    return matrix_to_pose(upright_matrix(x, 0.0, angle))


def test_continuous_symmetry_takes_the_reference_yaw() -> None:
    assert canonical_yaw(2.0, CONTINUOUS) == 0.0
    assert canonical_yaw(2.0, CONTINUOUS, reference=0.5) == pytest.approx(0.5)


@pytest.mark.parametrize(("yaw", "sym", "expected"), [
    (3.0, HALF_TURN, 3.0 - math.pi),
    (-2.5, HALF_TURN, -2.5 + math.pi),
    (2.0, QUARTER_TURN, 2.0 - math.pi / 2),
    (0.3, Symmetry(), 0.3),
    (7.0, Symmetry(), 7.0 - 2 * math.pi),
])  # fmt: skip
def test_discrete_symmetry_reduces_the_yaw(yaw: float, sym: Symmetry, expected: float) -> None:
    assert canonical_yaw(yaw, sym) == pytest.approx(expected)


def test_reduction_stays_close_to_the_reference() -> None:
    assert canonical_yaw(0.1, HALF_TURN, reference=3.0) == pytest.approx(0.1 - math.pi)  # wrapped


def test_rotation_error_honours_symmetry() -> None:
    assert rotation_error(_yaw(0.2), _yaw(0.2 + math.pi), HALF_TURN) == pytest.approx(0, abs=1e-7)
    assert rotation_error(_yaw(0.2), _yaw(0.2 + math.pi), Symmetry()) == pytest.approx(math.pi)
    assert rotation_error(_yaw(0.0), _yaw(1.0), CONTINUOUS) == pytest.approx(0, abs=1e-7)
    assert rotation_error(_yaw(0.0), _yaw(0.1 + math.pi / 2), QUARTER_TURN) == pytest.approx(0.1)
    tilted = Pose((0, 0, 0), (math.sin(0.05), 0.0, 0.0, math.cos(0.05)))  # 0.1 rad about x
    assert rotation_error(tilted, _yaw(2.0), CONTINUOUS) == pytest.approx(0.1)


def test_pose_error_is_distance_and_angle() -> None:
    pos, rot = pose_error(_yaw(0.0, x=0.01), _yaw(0.05), Symmetry())
    assert pos == pytest.approx(0.01) and rot == pytest.approx(0.05)


def test_pose_matrix_round_trip_and_table_frame() -> None:
    pose = Pose((0.1, -0.2, 0.3), (0.1, 0.7, -0.1, 0.7))
    back = matrix_to_pose(pose_to_matrix(pose))
    assert back.position == pytest.approx(pose.position)
    assert rotation_error(back, pose, Symmetry()) == pytest.approx(0, abs=1e-7)
    frame = table_frame((0.0, 0.0, 2.0, -0.2))  # z = 0.1, normal not unit length
    assert frame[2, 3] == pytest.approx(0.1) and frame[2, 2] == pytest.approx(1.0)
