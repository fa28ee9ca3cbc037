"""Conversions between what the UI shows (mm, degrees) and what the plan stores (m, rad)."""

from __future__ import annotations

import math

import pytest

from engine.types import JointConfig, ObjectModel, Pose, Region, Waypoint
from engine.units import (
    display_unit,
    format_value,
    pose_from_display,
    pose_to_display,
    quaternion_to_rpy,
    rpy_to_quaternion,
)


def test_display_units() -> None:
    assert display_unit("m").to_display(0.123) == pytest.approx(123.0)
    assert display_unit("m").from_display(123.0) == pytest.approx(0.123)
    assert display_unit("rad").to_display(math.pi / 2) == pytest.approx(90.0)
    assert display_unit("rad").suffix == "°" and display_unit("m").suffix == "mm"
    assert display_unit("px").factor == 1.0 and display_unit("px").suffix == "px"


@pytest.mark.parametrize(
    "rpy", [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1), (math.pi, 0.0, 0.0), (0.1, 1.4, -2.9)]
)
def test_rpy_quaternion_round_trip(rpy: tuple[float, float, float]) -> None:
    q = rpy_to_quaternion(*rpy)
    assert math.isclose(sum(v * v for v in q), 1.0)
    back = rpy_to_quaternion(*quaternion_to_rpy(q))
    # q and -q are the same rotation.
    assert (
        max(abs(a - b) for a, b in zip(q, back, strict=True)) < 1e-9
        or max(abs(a + b) for a, b in zip(q, back, strict=True)) < 1e-9
    )


def test_yaw_is_about_z() -> None:
    q = rpy_to_quaternion(0.0, 0.0, math.pi / 2)
    rotated = Pose((0, 0, 0), q).compose(Pose((1, 0, 0))).position
    assert rotated == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)


def test_pose_display_round_trip() -> None:
    shown = (100.0, -250.5, 30.0, 10.0, 20.0, 30.0)
    pose = pose_from_display(shown)
    assert pose.position == pytest.approx((0.1, -0.2505, 0.03))
    assert pose_to_display(pose) == pytest.approx(shown)


def test_format_value_uses_mm_and_degrees() -> None:
    pose = Pose((0.1, 0.2, 0.3), rpy_to_quaternion(0.0, 0.0, math.pi / 2))
    assert format_value(pose) == "(100.0, 200.0, 300.0) mm, rpy (0.0, 0.0, 90.0)°"
    assert format_value(JointConfig((0.0, math.pi))) == "(0.0, 180.0)°"
    assert (
        format_value(Region((0.0, 0.0, 0.5), 0.05)) == "centre (0.0, 0.0, 500.0) mm, radius 50.0 mm"
    )
    assert format_value(ObjectModel("cup")) == "cup"
    assert format_value(Waypoint("home", pose=Pose())) == "home (world)"
    assert format_value(0.5) == "0.5" and format_value(True) == "True"


def test_a_value_that_rounds_to_zero_reads_0_not_minus_0() -> None:
    pose = Pose((0.4210, 0.2802, -1.02e-05), (-5.6e-05, 4.1e-05, 0.0, 1.0))
    assert format_value(pose) == "(421.0, 280.2, 0.0) mm, rpy (0.0, 0.0, 0.0)°"
    assert format_value(JointConfig((-1e-9, 0.0))) == "(0.0, 0.0)°"
