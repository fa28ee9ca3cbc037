"""SimRobot: the simulated UR5 as other threads see it.

Every method may be called from any thread. Commands are queued to the physics thread and
return a ``CommandHandle`` at once; a refused command (unreachable pose, bad joints) returns
an already failed handle, never raises. State (joints, TCP pose) is read from the snapshot
the physics thread takes after each step.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from capabilities.robot.commands import CommandHandle
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.sim.arm_controller import MOVING_SPEED, ArmController
from capabilities.sim.errors import SimError
from capabilities.sim.physics_thread import PhysicsThread
from capabilities.sim.safety import ProtectiveStop
from capabilities.sim.transforms import pose_text_mm, pose_to_matrix
from engine.types import Pose

__all__ = ["SimRobot", "post_command"]


class SimRobot:
    """The arm of the simulated cell (UR5 CB3 on its stand).

    Args:
        physics: the physics thread.
        controller: the arm controller living on the physics thread.
        kin: kinematics of the mounted arm.
        home: the configured home joints.
        tcp_pose_in_flange: returns the current tool's TCP offset (depends on the tool held).
        body: pybullet body id of the robot; flange: link index of tool0.
        unlock_delay: simulated seconds after a protective stop before it can be unlocked.
    """

    def __init__(
        self,
        physics: PhysicsThread,
        controller: ArmController,
        kin: UR5Kinematics,
        home: Sequence[float],
        tcp_pose_in_flange: Callable[[], Pose],
        body: int,
        flange: int,
        unlock_delay: float = 5.0,
    ) -> None:
        self._physics = physics
        self._ctl = controller
        self._kin = kin
        self._home = tuple(float(v) for v in home)
        self._tcp = tcp_pose_in_flange
        self.body_id = body
        self._flange = flange
        self.unlock_delay = unlock_delay

    # ---------------------------------------------------------------- state

    def joint_positions(self) -> tuple[float, ...]:
        """Measured joint positions (rad), base to wrist."""
        return self._ctl.q_actual

    def joint_velocities(self) -> tuple[float, ...]:
        """Measured joint velocities (rad/s)."""
        return self._ctl.qd_actual

    def tcp_pose(self) -> Pose:
        """World pose of the current tool's TCP, from the measured joints."""
        return self._kin.forward(self._ctl.q_actual, self._tcp())

    def flange_pose(self) -> Pose:
        """World pose of the tool0 flange."""
        return self._kin.forward(self._ctl.q_actual)

    def tcp_offset(self) -> Pose:
        """The current tool's TCP in the flange frame."""
        return self._tcp()

    def is_moving(self) -> bool:
        """True while a move runs or any joint still turns."""
        return self._ctl.busy or max(abs(v) for v in self._ctl.qd_actual) > MOVING_SPEED

    def home_joints(self) -> tuple[float, ...]:
        """The configured home joints."""
        return self._home

    def flange_link(self) -> int:
        """Link index of tool0 in ``body_id`` (for a wrist camera)."""
        return self._flange

    # ---------------------------------------------------------------- kinematics

    def forward_kinematics(self, q: Sequence[float]) -> Pose:
        """World TCP pose of the current tool for joints ``q``."""
        return self._kin.forward(q, self._tcp())

    def inverse_kinematics(
        self, pose: Pose, near: Sequence[float] | None = None
    ) -> tuple[float, ...] | None:
        """Joints putting the current tool's TCP at ``pose``, nearest to ``near`` (default: now)."""
        return self._kin.inverse(
            pose, near if near is not None else self._ctl.q_actual, self._tcp()
        )

    # ---------------------------------------------------------------- motion

    def move_joints(
        self, q: Sequence[float], speed: float = 1.05, accel: float = 1.4
    ) -> CommandHandle:
        """MoveJ to joints ``q`` (rad) with joint speed (rad/s) and acceleration (rad/s^2)."""
        problem = self._check_joints(q) or _check_limits(speed, accel)
        if problem:
            return CommandHandle.failed("move_joints", problem)
        target = np.asarray(q, dtype=float)
        handle = self._handle("move_joints")
        return self._post(handle, lambda: self._ctl.start_joint_move(handle, target, speed, accel))

    def move_linear(self, pose: Pose, speed: float = 0.25, accel: float = 1.2) -> CommandHandle:
        """moveL: the TCP to ``pose`` on a straight line, speed (m/s), acceleration (m/s^2)."""
        problem = _check_limits(speed, accel)
        if problem:
            return CommandHandle.failed("move_linear", problem)
        if self.inverse_kinematics(pose) is None:
            return CommandHandle.failed("move_linear", f"unreachable: pose {pose_text_mm(pose)}")
        target = pose_to_matrix(pose)
        handle = self._handle("move_linear")
        return self._post(handle, lambda: self._ctl.start_linear_move(handle, target, speed, accel))

    def move_pose_joint_space(
        self, pose: Pose, speed: float = 1.05, accel: float = 1.4
    ) -> CommandHandle:
        """The TCP to ``pose`` by a joint move to the IK solution nearest the current joints."""
        q = self.inverse_kinematics(pose)
        if q is None:
            return CommandHandle.failed(
                "move_pose_joint_space", f"unreachable: pose {pose_text_mm(pose)}"
            )
        return self.move_joints(q, speed, accel)

    def stop(self, decel: float = 4.0) -> CommandHandle:
        """Decelerate any move to a halt (within 0.15 s); the handle finishes when halted."""
        handle = CommandHandle("stop")
        return self._post(handle, lambda: self._ctl.stop(handle, decel))

    # ---------------------------------------------------------------- protective stop

    def protective_stop(self) -> ProtectiveStop | None:
        """The protective stop the arm is in (a collision), or None."""
        return self._ctl.stopped

    def unlock_protective_stop(self, delay: float | None = None) -> None:
        """Unlock a protective stop now (nothing when there is none); blocks briefly.

        Args:
            delay: the least simulated time since the stop (default: the cell's setting).

        Raises:
            SimError: too early, as PolyScope refuses it (the message says how long is left).
        """
        wait = self.unlock_delay if delay is None else delay
        refused = self._physics.call(lambda _c: self._ctl.unlock(self._physics.time(), wait))
        if refused:
            raise SimError(refused)

    def clear_protective_stop(self) -> CommandHandle:
        """Unlock a protective stop as soon as the unlock delay allows; the handle finishes
        when the arm can move again (at once when it is not stopped).
        """
        handle = CommandHandle("clear_protective_stop")
        delay = self.unlock_delay
        return self._post(handle, lambda: self._ctl.clear_when_allowed(handle, delay))

    # ---------------------------------------------------------------- freedrive

    def set_freedrive(self, on: bool) -> None:
        """Start or stop hand guiding (stopping holds the arm where it is)."""
        self._physics.call(lambda _c: self._ctl.set_freedrive(on))

    def freedrive_active(self) -> bool:
        """True while hand guiding is on."""
        return self._ctl.freedrive.active

    def apply_tcp_wrench(
        self,
        force: Sequence[float],
        torque: Sequence[float] = (0.0, 0.0, 0.0),
        duration: float = 0.25,
    ) -> None:
        """Push the TCP (world-frame N and N m) for ``duration`` simulated seconds (freedrive)."""
        f, t = tuple(force), tuple(torque)
        self._physics.call(lambda _c: self._ctl.freedrive.apply_wrench(f, t, duration))

    def freedrive_drag_to(self, pose: Pose) -> CommandHandle:
        """In freedrive, drag the TCP to ``pose``; the handle finishes on arrival."""
        target = pose_to_matrix(pose)
        handle = CommandHandle("freedrive_drag_to", self._drag_canceller)
        return self._post(handle, lambda: self._ctl.freedrive.drag_to(handle, target))

    # ---------------------------------------------------------------- internals

    def _check_joints(self, q: Sequence[float]) -> str:
        values = list(q)
        if len(values) != 6 or not all(
            isinstance(v, (int, float)) and math.isfinite(v) for v in values
        ):
            return f"move_joints needs 6 finite joint angles, got {values}"
        if not self._kin.within_limits(values):
            return (
                f"unreachable: joints {[round(v, 4) for v in values]} are outside the joint limits"
            )
        return ""

    def _handle(self, name: str) -> CommandHandle:
        return CommandHandle(name, self._move_canceller)

    def _move_canceller(self, handle: CommandHandle) -> None:
        self._post(handle, lambda: self._ctl.cancel(handle))

    def _drag_canceller(self, handle: CommandHandle) -> None:
        self._post(handle, lambda: self._ctl.freedrive.cancel_drag(handle))

    def _post(self, handle: CommandHandle, action: Callable[[], None]) -> CommandHandle:
        return post_command(self._physics, handle, action)


def post_command(
    physics: PhysicsThread, handle: CommandHandle, action: Callable[[], None]
) -> CommandHandle:
    """Run ``action`` on the physics thread; any error there fails ``handle`` (never raises)."""

    def run(_client: int) -> None:
        try:
            action()
        except Exception as exc:
            handle.resolve(False, f"{handle.name} failed: {exc}")

    physics.track(handle)
    future = physics.post(run)
    if future.done() and future.exception() is not None:
        handle.resolve(False, f"{handle.name} failed: {future.exception()}")
    return handle


def _check_limits(speed: float, accel: float) -> str:
    if not (speed > 0 and accel > 0 and math.isfinite(speed) and math.isfinite(accel)):
        return f"speed and acceleration must be positive, got {speed}, {accel}"
    return ""
