"""Operations of the motion capability: moves, stop, pose and joint queries, conditions.

Every move returns a Job bound to the cell's command handle: the engine polls it, and halting
the node cancels the command, which stops the arm. Targets that cannot be reached fail the
node with a message that says "unreachable" and the pose in mm; nothing here raises through
the tick except :class:`OperationFailed`.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from capabilities.base import Capability, CapabilityEnv, CapabilityError
from capabilities.faults import fault_error
from capabilities.jobs import chain_jobs, job_from_handle
from capabilities.kit import InPort, OperationKind, joints, manifest, number, output, text
from capabilities.motion.backend import ARM, WORLD, ArmBackend, WorldBackend
from capabilities.motion.geometry import format_pose_mm
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import TargetResolver, reference_set, unused_reference
from engine.error_types import ErrorType
from engine.operations import BoundPort, Job, OperationCall, OperationFailed
from engine.types import JointConfig, ParamType, Pose, Waypoint, WaypointFrame

__all__ = ["capability", "scale"]

CAP = "motion"
# Nominal speeds: the UR defaults of moveJ and moveL; the speed ports scale them.
JOINT_SPEED = 1.05  # rad/s
JOINT_ACCEL = 1.4  # rad/s^2
LINEAR_SPEED = 0.25  # m/s
LINEAR_ACCEL = 1.2  # m/s^2

SPEED = number(
    "speed", 1.0, doc="fraction of the nominal speed (1.05 rad/s joint, 0.25 m/s linear), 0 to 2"
)
ACCEL = number(
    "accel",
    1.0,
    doc="fraction of the nominal acceleration (1.4 rad/s^2 joint, 1.2 m/s^2 linear), 0 to 2",
)

_MAX_SCALE = 2.0


def scale(call: OperationCall, port: InPort[float]) -> float:
    """A speed or acceleration fraction from a port, checked to be in (0, 2]."""
    value = call.input(port)  # a Number (validation checked the type, not the range)
    if not 0 < value <= _MAX_SCALE:
        raise OperationFailed(
            f"{port.name} must be above 0 and at most {_MAX_SCALE:g}, not {value}"
        )
    return value


def _joint_move(arm: ArmBackend, q: Sequence[float], call: OperationCall, describe: str) -> Any:
    handle = arm.move_joints(q, JOINT_SPEED * scale(call, SPEED), JOINT_ACCEL * scale(call, ACCEL))
    return job_from_handle(handle, describe)


def _linear_move(arm: ArmBackend, pose: Pose, call: OperationCall, describe: str) -> Any:
    handle = arm.move_linear(
        pose, LINEAR_SPEED * scale(call, SPEED), LINEAR_ACCEL * scale(call, ACCEL)
    )
    return job_from_handle(handle, describe)


def _via_approach(
    arm: ArmBackend, q: Sequence[float], pose: Pose, call: OperationCall, describe: str
) -> Job:
    """A joint move to the approach joints ``q``, then a straight line to ``pose``."""
    return chain_jobs(
        [
            ("approach", lambda: _joint_move(arm, q, call, describe)),
            ("descend", lambda: _linear_move(arm, pose, call, describe)),
        ]
    )


class _ArmOp:
    """An operation on the cell's arm."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._arm: ArmBackend = env.interface(ARM)


def _linear_to_joints(target: Waypoint) -> str:
    return (
        f"'mode' is linear, but the waypoint {target.name!r} is joint positions, which the arm "
        "reaches by a joint move: set 'mode' to joint, or teach the waypoint as a pose"
    )


def _move_to_rules(bound: Mapping[str, BoundPort]) -> Iterator[tuple[str, str]]:
    """move_to's inputs that its target would make it ignore (validation's side of
    :meth:`TargetResolver.resolve`, which refuses the same at run time for references).
    """
    target = bound.get("target")
    waypoint = target.value if target is not None else None
    if not isinstance(waypoint, Waypoint):
        return
    reference = bound.get("reference")
    given = reference is not None and (reference.ref is not None or reference_set(reference.value))
    if given and waypoint.frame in (WaypointFrame.JOINTS, WaypointFrame.WORLD):
        yield "reference", unused_reference(waypoint)
    mode = bound.get("mode")
    if mode is not None and mode.value == "linear" and waypoint.frame is WaypointFrame.JOINTS:
        yield "mode", _linear_to_joints(waypoint)


class MoveTo(_ArmOp):
    """motion.move_to: a pose or a waypoint in any frame, by a joint or a linear move."""

    TARGET = InPort[Waypoint | Pose](
        "target",
        (ParamType.WAYPOINT, ParamType.POSE),
        doc="where the tool goes (world pose, or a waypoint in any frame)",
    )
    REFERENCE = InPort[Pose | str](
        "reference",
        (ParamType.POSE, ParamType.TEXT),
        default="",
        doc="for a relative waypoint: the object's (marker's) pose, or a class name / marker id "
        "to look up; empty: the waypoint's own reference in the world model. For a Pose "
        "target: a pose, and the target is taken in its frame; or, the target being an "
        "object's pose, a grasp reference, 'cup' (its model's first grasp) or 'cup/rim'. "
        "Not for a waypoint in the world or joints frame",
    )
    MODE = text(
        "mode",
        "joint",
        choices=("joint", "linear"),
        doc="joint: fastest path in joint space; linear: a straight line of the tool (a grasp "
        "reference: joint to the approach, then straight to the grasp)",
    )
    MANIFEST = manifest(
        CAP,
        "move_to",
        OperationKind.ACTION,
        "Moves the tool to a pose or waypoint (relative waypoints follow the detected object; "
        "an object's pose with a grasp reference goes to that grasp through its approach).",
        TARGET,
        REFERENCE,
        MODE,
        SPEED,
        ACCEL,
        rules=(_move_to_rules,),
    )

    def __init__(self, env: CapabilityEnv) -> None:
        super().__init__(env)
        self._resolver = TargetResolver(_world(env), env.state)

    def start(self, call: OperationCall) -> Job:
        mode = call.input(self.MODE)
        current = self._arm.tcp_pose()
        given = call.input(self.TARGET)
        if mode == "linear" and isinstance(given, Waypoint) and given.frame is WaypointFrame.JOINTS:
            raise OperationFailed(_linear_to_joints(given))
        target = self._resolver.resolve(given, call.input(self.REFERENCE), current)
        if target.joints is not None:
            return _joint_move(
                self._arm, target.joints.positions, call, f"move to {target.describe}"
            )
        for index, pose in enumerate(target.poses):
            approach = target.approaches[index] if target.approaches else None
            q = self._arm.inverse_kinematics(approach or pose)
            if q is None or (approach and self._arm.inverse_kinematics(pose, near=q) is None):
                continue
            if index:
                call.log(f"symmetric equivalent {index} of {target.describe} is used")
            describe = f"move to {target.describe}"
            if approach is not None:
                return _via_approach(self._arm, q, pose, call, describe)
            if mode == "linear":
                return _linear_move(self._arm, pose, call, describe)
            return _joint_move(self._arm, q, call, describe)
        tried = (
            f" (none of {len(target.poses)} symmetric equivalents)" if len(target.poses) > 1 else ""
        )
        raise OperationFailed(
            f"unreachable: {target.describe}: tool pose {format_pose_mm(target.poses[0])}{tried}"
        )


class MoveJoints(_ArmOp):
    """motion.move_joints: a joint move to a JointConfig."""

    TARGET = joints("target", doc="joint positions, base to wrist")
    MANIFEST = manifest(
        CAP,
        "move_joints",
        OperationKind.ACTION,
        "Moves the arm to joint positions.",
        TARGET,
        SPEED,
        ACCEL,
    )

    def start(self, call: OperationCall) -> Job:
        return _joint_move(self._arm, call.input(self.TARGET).positions, call, "move_joints")


def _reachable(arm: ArmBackend, target: Pose) -> Pose:
    """``target``, or OperationFailed saying it is unreachable (with the pose in mm)."""
    if arm.inverse_kinematics(target) is None:
        raise OperationFailed(f"unreachable: pose {format_pose_mm(target)}")
    return target


class MoveRelative(_ArmOp):
    """motion.move_relative: a straight-line offset in the world or the tool frame."""

    DX = number("dx", 0.0, unit="m", doc="offset along x")
    DY = number("dy", 0.0, unit="m", doc="offset along y")
    DZ = number("dz", 0.0, unit="m", doc="offset along z")
    FRAME = text(
        "frame",
        "world",
        choices=("world", "tool"),
        doc="axes of the offset: the world's or the tool's",
    )
    MANIFEST = manifest(
        CAP,
        "move_relative",
        OperationKind.ACTION,
        "Moves the tool by an offset on a straight line.",
        DX,
        DY,
        DZ,
        FRAME,
        SPEED,
        ACCEL,
    )

    def start(self, call: OperationCall) -> Job:
        offset = (call.input(self.DX), call.input(self.DY), call.input(self.DZ))
        frame = call.input(self.FRAME)
        now = self._arm.tcp_pose()
        if frame == "world":
            x, y, z = now.position
            target = Pose((x + offset[0], y + offset[1], z + offset[2]), now.orientation)
        else:  # "tool" (the port's choices)
            target = now.compose(Pose(offset))
        _reachable(self._arm, target)
        mm = ", ".join(f"{v * 1000:.1f}" for v in offset)
        return _linear_move(self._arm, target, call, f"move by ({mm}) mm in the {frame} frame")


class MoveRelativeTool(_ArmOp):
    """motion.move_relative_tool: a straight-line move along the tool's own z axis."""

    DZ = number("dz", 0.0, unit="m", doc="offset along the tool's z (its approach)")
    MANIFEST = manifest(
        CAP,
        "move_relative_tool",
        OperationKind.ACTION,
        "Moves the tool by an offset along its own axes, on a straight line.",
        DZ,
        SPEED,
        ACCEL,
    )

    def start(self, call: OperationCall) -> Job:
        target = self._arm.tcp_pose().compose(Pose((0.0, 0.0, call.input(self.DZ))))
        _reachable(self._arm, target)
        return _linear_move(self._arm, target, call, "move along the tool's z")


class GoHome(_ArmOp):
    """motion.go_home: a joint move to the configured home."""

    MANIFEST = manifest(
        CAP, "go_home", OperationKind.ACTION, "Moves the arm to its home joints.", SPEED, ACCEL
    )

    def start(self, call: OperationCall) -> Job:
        return _joint_move(self._arm, self._arm.home_joints(), call, "go home")


class Stop(_ArmOp):
    """motion.stop: decelerate to a halt; SUCCESS when standing."""

    MANIFEST = manifest(
        CAP, "stop", OperationKind.ACTION, "Stops any arm motion; succeeds once the arm stands."
    )

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._arm.stop(), "stop")


class CurrentPose(_ArmOp):
    """motion.current_pose: writes the TCP pose."""

    MANIFEST = manifest(
        CAP,
        "current_pose",
        OperationKind.QUERY,
        "The tool's pose now (world frame).",
        output("pose", ParamType.POSE, doc="the tool pose"),
    )

    def start(self, call: OperationCall) -> Job:
        call.write("pose", self._arm.tcp_pose())
        return Job.done()


class CurrentJoints(_ArmOp):
    """motion.current_joints: writes the joint positions."""

    MANIFEST = manifest(
        CAP,
        "current_joints",
        OperationKind.QUERY,
        "The arm's joint positions now.",
        output("joints", ParamType.JOINTS, unit="rad", doc="joint positions"),
    )

    def start(self, call: OperationCall) -> Job:
        call.write("joints", JointConfig(self._arm.joint_positions()))
        return Job.done()


class IsMoving(_ArmOp):
    """motion.is_moving."""

    MANIFEST = manifest(CAP, "is_moving", OperationKind.CONDITION, "True while the arm moves.")

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._arm.is_moving())


class IsStopped(_ArmOp):
    """motion.is_stopped."""

    MANIFEST = manifest(
        CAP, "is_stopped", OperationKind.CONDITION, "True while the arm stands still."
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(not self._arm.is_moving())


class IsHome(_ArmOp):
    """motion.is_home: every joint within ``tolerance`` rad of home."""

    TOLERANCE = number("tolerance", 0.01, unit="rad", doc="largest joint difference allowed")
    MANIFEST = manifest(
        CAP,
        "is_home",
        OperationKind.CONDITION,
        "True when every joint is within a tolerance of the home position.",
        TOLERANCE,
    )

    def start(self, call: OperationCall) -> Job:
        tolerance = call.input(self.TOLERANCE)
        now, home = self._arm.joint_positions(), self._arm.home_joints()
        return Job.answer(max(abs(a - b) for a, b in zip(now, home, strict=True)) <= tolerance)


class ClearProtectiveStop(_ArmOp):
    """motion.clear_protective_stop."""

    MANIFEST = manifest(
        CAP,
        "clear_protective_stop",
        OperationKind.ACTION,
        "Clears a protective stop (after a collision): waits until the robot allows it (5 s "
        "after the stop on a UR), unlocks it and waits until the arm can move again. Succeeds "
        "at once when the arm is not stopped. An emergency stop, power off or a lost connection "
        "fails it with its type: those are for the operator.",
    )

    def start(self, call: OperationCall) -> Job:
        handle = self._arm.clear_protective_stop()
        job = Job(on_cancel=handle.cancel)

        def finished(_: Any) -> None:
            if handle.ok:
                job.succeed()
                return
            text = handle.message or "failed"
            error = ErrorType.TIMEOUT if "timed out" in text else fault_error(text)
            job.fail(f"clear protective stop: {text}", error)

        handle.add_done_callback(finished)
        return job


def _world(env: CapabilityEnv) -> WorldBackend | None:
    try:
        return env.interface(WORLD)
    except CapabilityError:
        return None  # relative waypoints then need their reference bound


def capability(symmetries: SymmetryTable | None = None) -> Capability:
    """The motion capability (requires ``arm``; reads ``world`` when the cell has one).

    Its per-cell state is the symmetry table targets on objects are resolved with.
    """
    table = symmetries if symmetries is not None else SymmetryTable()
    cap = Capability(
        CAP,
        "Moves the robot arm: poses, waypoints, joints, home.",
        requires=(ARM,),
        setup=lambda env: table,
    )
    cap.add(
        MoveTo,
        MoveJoints,
        MoveRelative,
        MoveRelativeTool,
        GoHome,
        Stop,
        ClearProtectiveStop,
        CurrentPose,
        CurrentJoints,
        IsMoving,
        IsStopped,
        IsHome,
    )
    return cap
