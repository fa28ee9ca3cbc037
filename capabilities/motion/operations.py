"""Operations of the motion capability: moves, stop, pose and joint queries, conditions.

Every move returns a Job bound to the cell's command handle: the engine polls it, and halting
the node cancels the command, which stops the arm. Targets that cannot be reached fail the
node with a message that says "unreachable" and the pose in mm; nothing here raises through
the tick except :class:`OperationFailed`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from capabilities.base import Capability, CapabilityEnv, CapabilityError
from capabilities.jobs import job_from_handle
from capabilities.motion import manifests as mf
from capabilities.motion.backend import ARM, WORLD, ArmBackend, WorldBackend
from capabilities.motion.geometry import format_pose_mm
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import TargetResolver
from engine.operations import Job, OperationCall, OperationFailed
from engine.types import JointConfig, Pose

__all__ = ["capability", "scale"]

_MAX_SCALE = 2.0


def scale(call: OperationCall, port: str) -> float:
    """A speed or acceleration fraction from a port, checked to be in (0, 2]."""
    value: float = call.input(port)  # a Number (validation checked the type, not the range)
    if not 0 < value <= _MAX_SCALE:
        raise OperationFailed(f"{port} must be above 0 and at most {_MAX_SCALE:g}, not {value}")
    return value


def _joint_move(arm: ArmBackend, q: Sequence[float], call: OperationCall, describe: str) -> Any:
    handle = arm.move_joints(
        q, mf.JOINT_SPEED * scale(call, "speed"), mf.JOINT_ACCEL * scale(call, "accel")
    )
    return job_from_handle(handle, describe)


def _linear_move(arm: ArmBackend, pose: Pose, call: OperationCall, describe: str) -> Any:
    handle = arm.move_linear(
        pose, mf.LINEAR_SPEED * scale(call, "speed"), mf.LINEAR_ACCEL * scale(call, "accel")
    )
    return job_from_handle(handle, describe)


class MoveTo:
    """motion.move_to: a pose or a waypoint in any frame, by a joint or a linear move."""

    def __init__(self, arm: ArmBackend, resolver: TargetResolver) -> None:
        self._arm = arm
        self._resolver = resolver

    def start(self, call: OperationCall) -> Job:
        mode = call.input("mode")
        current = self._arm.tcp_pose()
        target = self._resolver.resolve(call.input("target"), call.input("reference"), current)
        if target.joints is not None:
            return _joint_move(
                self._arm, target.joints.positions, call, f"move to {target.describe}"
            )
        for index, pose in enumerate(target.poses):
            q = self._arm.inverse_kinematics(pose)
            if q is None:
                continue
            if index:
                call.log(f"symmetric equivalent {index} of {target.describe} is used")
            describe = f"move to {target.describe}"
            if mode == "linear":
                return _linear_move(self._arm, pose, call, describe)
            return _joint_move(self._arm, q, call, describe)
        tried = (
            f" (none of {len(target.poses)} symmetric equivalents)" if len(target.poses) > 1 else ""
        )
        raise OperationFailed(
            f"unreachable: {target.describe}: tool pose {format_pose_mm(target.poses[0])}{tried}"
        )


class MoveJoints:
    """motion.move_joints: a joint move to a JointConfig."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        target: JointConfig = call.input("target")
        return _joint_move(self._arm, target.positions, call, "move_joints")


class MoveRelative:
    """motion.move_relative: a straight-line offset in the world or the tool frame."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        offset = (call.input("dx"), call.input("dy"), call.input("dz"))
        frame = call.input("frame")
        now = self._arm.tcp_pose()
        if frame == "world":
            x, y, z = now.position
            target = Pose((x + offset[0], y + offset[1], z + offset[2]), now.orientation)
        else:  # "tool" (the port's choices)
            target = now.compose(Pose(offset))
        if self._arm.inverse_kinematics(target) is None:
            raise OperationFailed(f"unreachable: pose {format_pose_mm(target)}")
        mm = ", ".join(f"{v * 1000:.1f}" for v in offset)
        return _linear_move(self._arm, target, call, f"move by ({mm}) mm in the {frame} frame")


class GoHome:
    """motion.go_home: a joint move to the configured home."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        return _joint_move(self._arm, self._arm.home_joints(), call, "go home")


class Stop:
    """motion.stop: decelerate to a halt; SUCCESS when standing."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._arm.stop(), "stop")


class CurrentPose:
    """motion.current_pose: writes the TCP pose."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        call.write("pose", self._arm.tcp_pose())
        return Job.done()


class CurrentJoints:
    """motion.current_joints: writes the joint positions."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        call.write("joints", JointConfig(self._arm.joint_positions()))
        return Job.done()


class IsMoving:
    """motion.is_moving (or, with ``negate``, motion.is_stopped)."""

    def __init__(self, arm: ArmBackend, negate: bool = False) -> None:
        self._arm = arm
        self._negate = negate

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._arm.is_moving() != self._negate)


class IsHome:
    """motion.is_home: every joint within ``tolerance`` rad of home."""

    def __init__(self, arm: ArmBackend) -> None:
        self._arm = arm

    def start(self, call: OperationCall) -> Job:
        tolerance = call.input("tolerance")
        now, home = self._arm.joint_positions(), self._arm.home_joints()
        return Job.answer(max(abs(a - b) for a, b in zip(now, home, strict=True)) <= tolerance)


def _world(env: CapabilityEnv) -> WorldBackend | None:
    try:
        return env.interface(WORLD)  # type: ignore[no-any-return]
    except CapabilityError:
        return None  # relative waypoints then need their reference bound


def capability(symmetries: SymmetryTable | None = None) -> Capability:
    """The motion capability (requires ``arm``; reads ``world`` when the cell has one)."""
    table = symmetries if symmetries is not None else SymmetryTable()
    cap = Capability(
        mf.CAP, "Moves the robot arm: poses, waypoints, joints, home.", requires=(ARM,)
    )
    m = mf.MANIFESTS

    def arm(env: CapabilityEnv) -> ArmBackend:
        return env.interface(ARM)  # type: ignore[no-any-return]

    cap.add(m["move_to"], lambda env: MoveTo(arm(env), TargetResolver(_world(env), table)))
    cap.add(m["move_joints"], lambda env: MoveJoints(arm(env)))
    cap.add(m["move_relative"], lambda env: MoveRelative(arm(env)))
    cap.add(m["go_home"], lambda env: GoHome(arm(env)))
    cap.add(m["stop"], lambda env: Stop(arm(env)))
    cap.add(m["current_pose"], lambda env: CurrentPose(arm(env)))
    cap.add(m["current_joints"], lambda env: CurrentJoints(arm(env)))
    cap.add(m["is_moving"], lambda env: IsMoving(arm(env)))
    cap.add(m["is_stopped"], lambda env: IsMoving(arm(env), negate=True))
    cap.add(m["is_home"], lambda env: IsHome(arm(env)))
    return cap
