"""Parameter value types of a plan: what a blackboard entry or an operation port holds.

Values are kept in SI units (m, rad, s) and poses are a position plus a unit quaternion
(x, y, z, w) in the world frame, z up. Every type has a JSON encoding for plan files and
traces; decoding checks the shape and names the JSON path of anything that is off.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from engine.errors import EngineError

__all__ = [
    "with_article",
    "ParamType",
    "Pose",
    "JointConfig",
    "ObjectModel",
    "Region",
    "Waypoint",
    "WaypointFrame",
    "MAX_VALUE_DEPTH",
    "ValueShapeError",
    "encode_value",
    "decode_value",
    "check_value",
    "type_of_value",
]


MAX_VALUE_DEPTH = 64
"""Deepest nesting of lists and objects in an ``Any`` value (deeper is refused on reading and
cut short on writing, so no value can exhaust the interpreter's recursion limit)."""


class ValueShapeError(EngineError):
    """A value does not have the shape its type needs.

    Attributes:
        path: the JSON path of the value.
        expected: what its type needs.
        got: the value.
        got_text: a short description of the value for messages.
    """

    def __init__(self, path: str, expected: str, got: Any, got_text: str | None = None) -> None:
        self.path = path
        self.expected = expected
        self.got = got
        self.got_text = _describe(got) if got_text is None else got_text
        super().__init__(f"{path}: expected {expected}, got {self.got_text}")


def with_article(word: str) -> str:
    """``word`` after the article its sound takes: "a Pose", "an ObjectModel"."""
    return f"{'an' if word[:1].lower() in 'aeiou' else 'a'} {word}"


def _describe(value: Any) -> str:
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{type(value).__name__} {text}"


class ParamType(str, enum.Enum):
    """The types a parameter can have (DESIGN.md section 4)."""

    POSE = "Pose"
    JOINTS = "JointConfig"
    OBJECT = "ObjectModel"
    REGION = "Region"
    WAYPOINT = "Waypoint"
    NUMBER = "Number"
    TEXT = "Text"
    BOOL = "Bool"
    DURATION = "Duration"
    ANY = "Any"


@dataclass(frozen=True)
class Pose:
    """A rigid transform: position (m) and unit quaternion (x, y, z, w)."""

    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", tuple(float(v) for v in self.position))
        q = tuple(float(v) for v in self.orientation)
        norm = math.sqrt(sum(v * v for v in q))
        if len(q) != 4 or not norm > 1e-9:
            raise ValueError(f"orientation must be a non-zero quaternion (x, y, z, w), got {q}")
        # Normalising an already unit quaternion again changes its last bits, and then a
        # save -> load -> save would not be byte-identical.
        if abs(norm - 1.0) > 1e-12:
            q = tuple(v / norm for v in q)
        object.__setattr__(self, "orientation", q)
        if len(self.position) != 3:
            raise ValueError(f"position must have 3 values, got {self.position}")

    @classmethod
    def of(
        cls, position: Sequence[float], orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0)
    ) -> Pose:
        """A pose from any sequences of numbers (a list, a numpy array); lengths are checked."""
        if len(position) != 3 or len(orientation) != 4:
            raise ValueError(
                f"a pose needs 3 + 4 numbers, got {len(position)} + {len(orientation)}"
            )
        x, y, z = (float(v) for v in position)
        qx, qy, qz, qw = (float(v) for v in orientation)
        return cls((x, y, z), (qx, qy, qz, qw))

    def compose(self, other: Pose) -> Pose:
        """This transform followed by ``other`` (``self * other``)."""
        rotated = _rotate(self.orientation, other.position)
        position = (
            self.position[0] + rotated[0],
            self.position[1] + rotated[1],
            self.position[2] + rotated[2],
        )
        return Pose(position, _quat_mul(self.orientation, other.orientation))

    def inverse(self) -> Pose:
        """The inverse transform."""
        x, y, z, w = self.orientation
        conj = (-x, -y, -z, w)
        p = _rotate(conj, self.position)
        return Pose((-p[0], -p[1], -p[2]), conj)


def _quat_mul(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _rotate(q: tuple[float, float, float, float], v: Sequence[float]) -> tuple[float, float, float]:
    x, y, z, _w = _quat_mul(_quat_mul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


@dataclass(frozen=True)
class JointConfig:
    """Joint positions of the arm in radians, base to wrist."""

    positions: tuple[float, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "positions", tuple(float(v) for v in self.positions))


@dataclass(frozen=True)
class ObjectModel:
    """A name from the object library (``"cup"``, ``"plate_4_holes"``)."""

    name: str


@dataclass(frozen=True)
class Region:
    """A sphere in the world frame: centre (m) and radius (m)."""

    center: tuple[float, float, float]
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", tuple(float(v) for v in self.center))
        object.__setattr__(self, "radius", float(self.radius))


class WaypointFrame(str, enum.Enum):
    """What a waypoint's pose is relative to."""

    WORLD = "world"
    OBJECT = "object"
    MARKER = "marker"
    JOINTS = "joints"


@dataclass(frozen=True)
class Waypoint:
    """A named pose: absolute, relative to an object class or marker, or in joint space.

    A relative waypoint stores the tool pose in the object's (or marker's) frame, the
    paper's "smart waypoint"; it is composed with the detected pose at run time.
    """

    name: str
    frame: WaypointFrame = WaypointFrame.WORLD
    pose: Pose | None = None
    joints: JointConfig | None = None
    reference: str = ""  # object class name or marker id for relative frames

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame", WaypointFrame(self.frame))
        if self.frame is WaypointFrame.JOINTS:
            if self.joints is None:
                raise ValueError(f"waypoint {self.name!r} in joint space needs joints")
        elif self.pose is None:
            raise ValueError(f"waypoint {self.name!r} needs a pose")
        if self.frame in (WaypointFrame.OBJECT, WaypointFrame.MARKER) and not self.reference:
            raise ValueError(
                f"waypoint {self.name!r} relative to a {self.frame.value} needs a reference"
            )


# --------------------------------------------------------------------------- JSON


def _floats(value: Any, n: int, path: str) -> tuple[float, ...]:
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        raise ValueShapeError(path, f"a list of {n} numbers", value)
    return tuple(float(v) for v in value)


def _floats3(value: Any, path: str) -> tuple[float, float, float]:
    x, y, z = _floats(value, 3, path)
    return (x, y, z)


def _floats4(value: Any, path: str) -> tuple[float, float, float, float]:
    x, y, z, w = _floats(value, 4, path)
    return (x, y, z, w)


def _obj(
    value: Any, path: str, keys: Sequence[str], optional: Sequence[str] = ()
) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise ValueShapeError(path, f"an object with {', '.join(keys)}", value)
    for key in keys:
        if key not in value:
            raise ValueShapeError(f"{path}.{key}", "a value (missing)", None)
    for key in value:
        if key not in keys and key not in optional:
            raise ValueShapeError(f"{path}.{key}", "no such field", value[key])
    return value


def _decode_pose(value: Any, path: str) -> Pose:
    obj = _obj(value, path, ("position", "orientation"))
    position = _floats3(obj["position"], f"{path}.position")
    orientation = _floats4(obj["orientation"], f"{path}.orientation")
    try:
        return Pose(position, orientation)
    except ValueError as exc:
        raise ValueShapeError(f"{path}.orientation", "a non-zero quaternion", orientation) from exc


def _encode_pose(pose: Pose) -> dict[str, Any]:
    return {"position": list(pose.position), "orientation": list(pose.orientation)}


def _decode_joints(value: Any, path: str) -> JointConfig:
    if not isinstance(value, list) or not value:
        raise ValueShapeError(path, "a list of joint angles in radians", value)
    return JointConfig(_floats(value, len(value), path))


def _decode_number(value: Any, path: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueShapeError(path, "a finite number", value)
    return float(value)


def _decode_text(value: Any, path: str) -> str:
    if not isinstance(value, str):
        raise ValueShapeError(path, "a text string", value)
    return value


def _decode_bool(value: Any, path: str) -> bool:
    if not isinstance(value, bool):
        raise ValueShapeError(path, "true or false", value)
    return value


def _decode_duration(value: Any, path: str) -> float:
    seconds = _decode_number(value, path)
    if seconds < 0:
        raise ValueShapeError(path, "a duration in seconds, not negative", value)
    return seconds


def _decode_object(value: Any, path: str) -> ObjectModel:
    return ObjectModel(_decode_text(value, path))


def _decode_region(value: Any, path: str) -> Region:
    obj = _obj(value, path, ("center", "radius"))
    radius = _decode_number(obj["radius"], f"{path}.radius")
    if radius <= 0:
        raise ValueShapeError(f"{path}.radius", "a radius above 0 m", radius)
    return Region(_floats3(obj["center"], f"{path}.center"), radius)


def _decode_waypoint(value: Any, path: str) -> Waypoint:
    obj = _obj(value, path, ("name", "frame"), ("pose", "joints", "reference"))
    name = _decode_text(obj["name"], f"{path}.name")
    frames = [f.value for f in WaypointFrame]
    if obj["frame"] not in frames:
        raise ValueShapeError(f"{path}.frame", f"one of {frames}", obj["frame"])
    pose = _decode_pose(obj["pose"], f"{path}.pose") if "pose" in obj else None
    joints = _decode_joints(obj["joints"], f"{path}.joints") if "joints" in obj else None
    reference = _decode_text(obj.get("reference", ""), f"{path}.reference")
    try:
        return Waypoint(name, WaypointFrame(obj["frame"]), pose, joints, reference)
    except ValueError as exc:
        raise ValueShapeError(path, str(exc), value) from exc


def _encode_waypoint(wp: Waypoint) -> dict[str, Any]:
    out: dict[str, Any] = {"name": wp.name, "frame": wp.frame.value}
    if wp.pose is not None:
        out["pose"] = _encode_pose(wp.pose)
    if wp.joints is not None:
        out["joints"] = list(wp.joints.positions)
    if wp.reference:
        out["reference"] = wp.reference
    return out


def _decode_any(value: Any, path: str) -> Any:
    stack: list[tuple[str, Any, int]] = [(path, value, 1)]
    while stack:
        here, item, depth = stack.pop()
        if isinstance(item, (list, dict)):
            if depth > MAX_VALUE_DEPTH:
                raise ValueShapeError(
                    here,
                    f"a value nested at most {MAX_VALUE_DEPTH} levels deep",
                    item,
                    "deeper nesting",
                )
            pairs = item.items() if isinstance(item, dict) else enumerate(item)
            stack.extend((_at(here, k), v, depth + 1) for k, v in pairs)
    return value


def _at(path: str, key: Any) -> str:
    return f"{path}[{key}]" if isinstance(key, int) else f"{path}.{key}"


_DECODERS: dict[ParamType, Callable[[Any, str], Any]] = {
    ParamType.POSE: _decode_pose,
    ParamType.JOINTS: _decode_joints,
    ParamType.OBJECT: _decode_object,
    ParamType.REGION: _decode_region,
    ParamType.WAYPOINT: _decode_waypoint,
    ParamType.NUMBER: _decode_number,
    ParamType.TEXT: _decode_text,
    ParamType.BOOL: _decode_bool,
    ParamType.DURATION: _decode_duration,
    ParamType.ANY: _decode_any,
}

_PY_TYPES: dict[ParamType, type | tuple[type, ...]] = {
    ParamType.POSE: Pose,
    ParamType.JOINTS: JointConfig,
    ParamType.OBJECT: ObjectModel,
    ParamType.REGION: Region,
    ParamType.WAYPOINT: Waypoint,
    ParamType.NUMBER: (int, float),
    ParamType.TEXT: str,
    ParamType.BOOL: bool,
    ParamType.DURATION: (int, float),
    ParamType.ANY: object,
}


def decode_value(ptype: ParamType, value: Any, path: str = "$") -> Any:
    """Turn the JSON form of a value into its Python value, or raise ValueShapeError."""
    return _DECODERS[ptype](value, path)


def encode_value(value: Any, depth: int = 1) -> Any:
    """The JSON form of a value of any parameter type.

    Lists and objects nested deeper than :data:`MAX_VALUE_DEPTH` are cut short: the part
    below that depth becomes the text ``"<nested deeper than N levels>"``, so a display or a
    trace of any value never exhausts the recursion limit.
    """
    if isinstance(value, Pose):
        return _encode_pose(value)
    if isinstance(value, JointConfig):
        return list(value.positions)
    if isinstance(value, ObjectModel):
        return value.name
    if isinstance(value, Region):
        return {"center": list(value.center), "radius": value.radius}
    if isinstance(value, Waypoint):
        return _encode_waypoint(value)
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    if isinstance(value, (list, tuple, dict)) and depth > MAX_VALUE_DEPTH:
        return f"<nested deeper than {MAX_VALUE_DEPTH} levels>"
    if isinstance(value, (list, tuple)):
        return [encode_value(v, depth + 1) for v in value]
    if isinstance(value, dict):
        return {str(k): encode_value(v, depth + 1) for k, v in value.items()}
    return repr(value)


def check_value(ptype: ParamType, value: Any) -> bool:
    """True when a Python value is of the given parameter type."""
    if ptype in (ParamType.NUMBER, ParamType.DURATION) and isinstance(value, bool):
        return False
    return isinstance(value, _PY_TYPES[ptype])


def type_of_value(value: Any) -> ParamType:
    """The parameter type of a Python value (ANY when none fits)."""
    for ptype in (
        ParamType.BOOL,
        ParamType.NUMBER,
        ParamType.TEXT,
        ParamType.POSE,
        ParamType.JOINTS,
        ParamType.OBJECT,
        ParamType.REGION,
        ParamType.WAYPOINT,
    ):
        if check_value(ptype, value):
            return ptype
    return ParamType.ANY
