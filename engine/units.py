"""What people read versus what the plan stores: mm and degrees shown, m and rad inside.

The Instructor's editors and panels and ``costar run`` show values through these pure
functions, so the command line reads like the GUI; :func:`parse_shown` reads back what a
person types in the same units (the Blackboard panel's edits while a run is paused). Orientation is shown as roll, pitch, yaw
about the fixed world axes x, y, z (R = Rz(yaw) Ry(pitch) Rx(roll)), the convention of ROS
and of the UR teach pendant's RPY view.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from engine.errors import EngineError
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Region, Waypoint, with_article

__all__ = [
    "DisplayUnit",
    "display_unit",
    "rpy_to_quaternion",
    "quaternion_to_rpy",
    "pose_to_display",
    "pose_from_display",
    "format_value",
    "parse_shown",
    "ShownValueError",
]


@dataclass(frozen=True)
class DisplayUnit:
    """How a stored SI unit is shown: ``shown = stored * factor``, with ``suffix``."""

    suffix: str
    factor: float
    decimals: int

    def to_display(self, value: float) -> float:
        return value * self.factor

    def from_display(self, value: float) -> float:
        return value / self.factor


_DEG = 180.0 / math.pi
_UNITS: dict[str, DisplayUnit] = {
    "m": DisplayUnit("mm", 1000.0, 2),
    "m/s": DisplayUnit("mm/s", 1000.0, 2),
    "m/s^2": DisplayUnit("mm/s²", 1000.0, 2),
    "rad": DisplayUnit("°", _DEG, 3),
    "rad/s": DisplayUnit("°/s", _DEG, 3),
    "rad/s^2": DisplayUnit("°/s²", _DEG, 3),
}


def display_unit(si_unit: str) -> DisplayUnit:
    """The on-screen unit of an SI unit; units the UI keeps as they are get factor 1."""
    if si_unit in _UNITS:
        return _UNITS[si_unit]
    return DisplayUnit(si_unit, 1.0, 3 if si_unit else 4)


def rpy_to_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """Fixed-axis roll, pitch, yaw (rad) to a unit quaternion (x, y, z, w)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def quaternion_to_rpy(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    """A unit quaternion (x, y, z, w) to fixed-axis roll, pitch, yaw (rad)."""
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    # Clamped: rounding can push the sine just past 1 at pitch = +-90 degrees.
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def pose_to_display(pose: Pose) -> tuple[float, ...]:
    """(x, y, z in mm, roll, pitch, yaw in degrees)."""
    position = tuple(v * 1000.0 for v in pose.position)
    angles = tuple(a * _DEG for a in quaternion_to_rpy(pose.orientation))
    return position + angles


def pose_from_display(values: tuple[float, ...]) -> Pose:
    """The inverse of :func:`pose_to_display`."""
    x, y, z, roll, pitch, yaw = values
    q = rpy_to_quaternion(roll / _DEG, pitch / _DEG, yaw / _DEG)
    return Pose((x / 1000.0, y / 1000.0, z / 1000.0), q)


def _one_decimal(value: float) -> str:
    """``value`` with one decimal, never "-0.0" (a pose a hair under the table reads 0.0)."""
    text = f"{value:.1f}"
    return "0.0" if text == "-0.0" else text


def _mm(values: tuple[float, ...]) -> str:
    return ", ".join(_one_decimal(v * 1000.0) for v in values)


def format_value(value: Any) -> str:
    """A value as a person reads it: poses and regions in mm and degrees, joints in degrees."""
    if isinstance(value, Pose):
        shown = pose_to_display(value)
        angles = ", ".join(_one_decimal(a) for a in shown[3:])
        return f"({_mm(value.position)}) mm, rpy ({angles})°"
    if isinstance(value, JointConfig):
        return "(" + ", ".join(_one_decimal(p * _DEG) for p in value.positions) + ")°"
    if isinstance(value, Region):
        return f"centre ({_mm(value.center)}) mm, radius {value.radius * 1000.0:.1f} mm"
    if isinstance(value, ObjectModel):
        return value.name
    if isinstance(value, Waypoint):
        where = value.frame.value + (f" {value.reference}" if value.reference else "")
        return f"{value.name} ({where})"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    return str(value)


class ShownValueError(EngineError):
    """Typed text that is not a value of the type asked for; the message says what is."""


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_TRUE = {"true", "yes", "on", "1"}
_FALSE = {"false", "no", "off", "0"}

# What each type takes, in the units shown (for the messages).
_HOW: dict[ParamType, str] = {
    ParamType.POSE: "x, y, z in mm and roll, pitch, yaw in degrees, "
    "e.g. (400, 0, 300) mm, rpy (180, 0, 0)°",
    ParamType.JOINTS: "the joint angles in degrees, e.g. (0, -90, 90, -90, -90, 0)°",
    ParamType.REGION: "a centre x, y, z and a radius in mm, e.g. centre (400, 0, 300) mm, "
    "radius 100 mm",
    ParamType.NUMBER: "a number, e.g. 2.5",
    ParamType.DURATION: "seconds, e.g. 1.5",
    ParamType.BOOL: "true or false",
    ParamType.OBJECT: "an object's name, e.g. cup",
}


def _numbers(text: str) -> list[float]:
    """The numbers in ``text``; the words and brackets around them ("mm", "rpy") are skipped,
    but any other letter makes the text no list of numbers.
    """
    rest = _NUMBER.sub(" ", text)
    for word in ("centre", "center", "radius", "rpy", "mm", "deg", "°", "s"):
        rest = rest.replace(word, " ")
    if any(c.isalnum() for c in rest):
        raise ValueError(text)
    return [float(n) for n in _NUMBER.findall(text)]


def _parse(ptype: ParamType, text: str) -> Any:
    if ptype in (ParamType.NUMBER, ParamType.DURATION):
        (value,) = _numbers(text)
        return value
    if ptype is ParamType.BOOL:
        if text.lower() in _TRUE | _FALSE:
            return text.lower() in _TRUE
        raise ValueError(text)
    if ptype is ParamType.POSE:
        x, y, z, roll, pitch, yaw = _numbers(text)
        return pose_from_display((x, y, z, roll, pitch, yaw))
    if ptype is ParamType.JOINTS:
        angles = _numbers(text)
        if not angles:
            raise ValueError(text)
        return JointConfig(tuple(a / _DEG for a in angles))
    if ptype is ParamType.REGION:
        x, y, z, radius = _numbers(text)
        if radius <= 0:
            raise ValueError(text)
        return Region((x / 1000.0, y / 1000.0, z / 1000.0), radius / 1000.0)
    if ptype is ParamType.OBJECT:
        if not text or any(c.isspace() for c in text):
            raise ValueError(text)
        return ObjectModel(text)
    raise AssertionError(ptype)


def parse_shown(ptype: ParamType, text: str, name: str = "the value") -> Any:
    """What a person typed, in the units :func:`format_value` shows (mm, degrees), as a value
    of ``ptype`` in SI units.

    ``ParamType.ANY`` takes a number, true or false, else the text. Raises
    ShownValueError naming ``name`` and what its type takes; a Waypoint is not typed (it is
    taught or picked in the Waypoints panel).
    """
    text = text.strip()
    if ptype is ParamType.TEXT:
        return text
    if ptype is ParamType.ANY:
        for guess in (ParamType.NUMBER, ParamType.BOOL):
            try:
                return _parse(guess, text)
            except ValueError:
                continue
        return text
    if ptype is ParamType.WAYPOINT:
        raise ShownValueError(
            f"{name} holds a Waypoint: pick or teach one in the Waypoints panel, it is not typed"
        )
    try:
        return _parse(ptype, text)
    except (ValueError, ZeroDivisionError) as exc:
        raise ShownValueError(
            f"{name} holds {with_article(ptype.value)}: type {_HOW[ptype]} (not {text!r})"
        ) from exc
