"""Manifests of the motion capability: ids, kinds, typed ports and docs (no code)."""

from __future__ import annotations

from capabilities.kit import manifest
from engine.operations import Direction, OperationKind, PortSpec
from engine.types import ParamType

__all__ = [
    "CAP",
    "JOINT_ACCEL",
    "JOINT_SPEED",
    "LINEAR_ACCEL",
    "LINEAR_SPEED",
    "MANIFESTS",
]

CAP = "motion"
# Nominal speeds: the UR defaults of moveJ and moveL; the speed ports scale them.
JOINT_SPEED = 1.05  # rad/s
JOINT_ACCEL = 1.4  # rad/s^2
LINEAR_SPEED = 0.25  # m/s
LINEAR_ACCEL = 1.2  # m/s^2

_N = (ParamType.NUMBER,)
SPEED = PortSpec(
    "speed", _N, default=1.0,
    doc="fraction of the nominal speed (1.05 rad/s joint, 0.25 m/s linear), 0 to 2",
)  # fmt: skip
ACCEL = PortSpec(
    "accel", _N, default=1.0,
    doc="fraction of the nominal acceleration (1.4 rad/s^2 joint, 1.2 m/s^2 linear), 0 to 2",
)  # fmt: skip


MOVE_TO = manifest(CAP, "move_to",
    OperationKind.ACTION,
    "Moves the tool to a pose or waypoint (relative waypoints follow the detected object).",
    PortSpec(
        "target", (ParamType.WAYPOINT, ParamType.POSE),
        doc="where the tool goes (world pose, or a waypoint in any frame)",
    ),
    PortSpec(
        "reference", (ParamType.POSE, ParamType.TEXT), default="",
        doc="for a relative waypoint: the object's (marker's) pose, or a class name / marker id "
        "to look up; empty: the waypoint's own reference in the world model",
    ),
    PortSpec(
        "mode", (ParamType.TEXT,), default="joint", choices=("joint", "linear"),
        doc="joint: fastest path in joint space; linear: a straight line of the tool",
    ),
    SPEED,
    ACCEL,
)  # fmt: skip

MOVE_JOINTS = manifest(
    CAP,
    "move_joints",
    OperationKind.ACTION,
    "Moves the arm to joint positions.",
    PortSpec("target", (ParamType.JOINTS,), unit="rad", doc="joint positions, base to wrist"),
    SPEED,
    ACCEL,
)

MOVE_RELATIVE = manifest(CAP, "move_relative",
    OperationKind.ACTION,
    "Moves the tool by an offset on a straight line.",
    PortSpec("dx", _N, default=0.0, unit="m", doc="offset along x"),
    PortSpec("dy", _N, default=0.0, unit="m", doc="offset along y"),
    PortSpec("dz", _N, default=0.0, unit="m", doc="offset along z"),
    PortSpec(
        "frame", (ParamType.TEXT,), default="world", choices=("world", "tool"),
        doc="axes of the offset: the world's or the tool's",
    ),
    SPEED,
    ACCEL,
)  # fmt: skip

GO_HOME = manifest(
    CAP, "go_home", OperationKind.ACTION, "Moves the arm to its home joints.", SPEED, ACCEL
)

STOP = manifest(
    CAP, "stop", OperationKind.ACTION, "Stops any arm motion; succeeds once the arm stands."
)

CURRENT_POSE = manifest(
    CAP,
    "current_pose",
    OperationKind.QUERY,
    "The tool's pose now (world frame).",
    PortSpec("pose", (ParamType.POSE,), Direction.OUT, doc="the tool pose"),
)

CURRENT_JOINTS = manifest(
    CAP,
    "current_joints",
    OperationKind.QUERY,
    "The arm's joint positions now.",
    PortSpec("joints", (ParamType.JOINTS,), Direction.OUT, unit="rad", doc="joint positions"),
)

IS_MOVING = manifest(CAP, "is_moving", OperationKind.CONDITION, "True while the arm moves.")
IS_STOPPED = manifest(
    CAP, "is_stopped", OperationKind.CONDITION, "True while the arm stands still."
)
IS_HOME = manifest(
    CAP,
    "is_home",
    OperationKind.CONDITION,
    "True when every joint is within a tolerance of the home position.",
    PortSpec("tolerance", _N, default=0.01, unit="rad", doc="largest joint difference allowed"),
)

MANIFESTS = {
    m.id.split(".", 1)[1]: m
    for m in (
        MOVE_TO, MOVE_JOINTS, MOVE_RELATIVE, GO_HOME, STOP,
        CURRENT_POSE, CURRENT_JOINTS, IS_MOVING, IS_STOPPED, IS_HOME,
    )
}  # fmt: skip
