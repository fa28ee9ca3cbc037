"""parse_shown: what a person types, in mm and degrees, read back as SI values."""

from __future__ import annotations

import math

import pytest

from engine.types import JointConfig, ObjectModel, ParamType, Pose, Region
from engine.units import ShownValueError, format_value, parse_shown


def test_a_pose_in_mm_and_degrees_reads_back_as_shown() -> None:
    pose = parse_shown(ParamType.POSE, "(500, 100, 250) mm, rpy (180, 0, 90)°")
    assert isinstance(pose, Pose) and pose.position == (0.5, 0.1, 0.25)
    assert format_value(pose) == "(500.0, 100.0, 250.0) mm, rpy (180.0, 0.0, 90.0)°"
    assert parse_shown(ParamType.POSE, "500 100 250 180 0 90").position == (0.5, 0.1, 0.25)


@pytest.mark.parametrize(
    ("ptype", "text", "value"),
    [
        (ParamType.JOINTS, "(0, -90, 90)°", JointConfig((0.0, -math.pi / 2, math.pi / 2))),
        (ParamType.REGION, "centre (400, 0, 300) mm, radius 100 mm", Region((0.4, 0, 0.3), 0.1)),
        (ParamType.NUMBER, " 2.5 ", 2.5),
        (ParamType.DURATION, "1.5 s", 1.5),
        (ParamType.BOOL, "False", False),
        (ParamType.OBJECT, "cup", ObjectModel("cup")),
        (ParamType.TEXT, "hello world", "hello world"),
        (ParamType.ANY, "3", 3.0),
        (ParamType.ANY, "yes", True),
        (ParamType.ANY, "a cup", "a cup"),
    ],
)
def test_each_type_reads_what_it_shows(ptype: ParamType, text: str, value: object) -> None:
    assert parse_shown(ptype, text) == value


@pytest.mark.parametrize(
    ("ptype", "text", "message"),
    [
        (ParamType.POSE, "(1, 2, 3)", "TARGET holds a Pose: type x, y, z in mm and roll"),
        (ParamType.NUMBER, "fast", "TARGET holds a Number: type a number"),
        (ParamType.BOOL, "maybe", "TARGET holds a Bool: type true or false"),
        (ParamType.REGION, "centre (0, 0, 0) mm, radius 0 mm", "TARGET holds a Region"),
        (ParamType.WAYPOINT, "home", "pick or teach one in the Waypoints panel"),
    ],
)
def test_bad_text_is_refused_naming_the_entry_and_its_type(
    ptype: ParamType, text: str, message: str
) -> None:
    with pytest.raises(ShownValueError, match=message):
        parse_shown(ptype, text, "TARGET")
