"""The arm's joint controller; runs on the physics thread only.

It plays a trajectory through pybullet's POSITION_CONTROL motors (target position plus
feed-forward velocity, forces well above gravity load) so the arm is a physical body that
pushes objects, and finishes a move once the joints have settled on the target; a move held
back short of it (blocked) fails and the arm holds where it stopped, no longer pressing on
what blocked it. Stopping slows trajectory time down to zero, so a stopped arm stays on its
path. A collision (see
``safety.py``) is a protective stop: the arm holds where it is at once, the move fails with
the fault's words, and every motion is refused until the stop is unlocked.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from capabilities.bullet import pybullet
from capabilities.robot.commands import CommandHandle
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.sim.freedrive import Freedrive
from capabilities.sim.safety import CollisionWatch, ProtectiveStop
from capabilities.sim.trajectory import (
    CartesianTrajectory,
    JointTrajectory,
    LinearPathError,
    plan_linear,
)
from capabilities.sim.transforms import rotation_angle
from capabilities.sim.world import World

__all__ = ["MOVING_SPEED", "ArmController"]

Trajectory = JointTrajectory | CartesianTrajectory
_FORCES = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)  # 2x the UR5's rated joint torques (N m)
_POSITION_GAIN = 0.6
_VELOCITY_GAIN = 1.0
_SETTLED_RAD = 5e-5
MOVING_SPEED = 1e-3  # rad/s: slower joints count as standing still (a move ends only then)
_SETTLE_TIMEOUT = 0.5  # s after the trajectory ends
_MAX_STOP_TIME = 0.15  # s: a stop always completes well within 0.2 s
_TOL_M = 1e-3
_TOL_RAD = math.radians(0.5)


@dataclass
class _Motion:
    trajectory: Trajectory
    handle: CommandHandle
    elapsed: float = 0.0  # trajectory time
    rate: float = 1.0  # trajectory seconds per simulated second
    stop_step: float = 0.0  # rate decrease per step while stopping
    stop_handles: list[CommandHandle] = field(default_factory=list)
    stop_reason: str = ""
    settle: float = 0.0


class ArmController:
    """Plays joint trajectories on the UR5's motors, handles stop and freedrive.

    Args:
        client: the pybullet client.
        world: the cell's built world: the robot's body and its arm's joints.
        kin: the UR5's kinematics.
        dt: the physics time step (s).
        tcp: the TCP in the flange frame of the tool held now (4 x 4 matrix).
    """

    def __init__(
        self,
        client: int,
        world: World,
        kin: UR5Kinematics,
        dt: float,
        tcp: Callable[[], np.ndarray],
    ) -> None:
        self._client = client
        self._body = world.robot
        self._joints = world.arm_joints
        self._kin = kin
        self._dt = dt
        self._tcp = tcp
        self.q_actual: tuple[float, ...] = tuple(
            s[0] for s in pybullet.getJointStates(self._body, self._joints, physicsClientId=client)
        )
        self.qd_actual: tuple[float, ...] = (0.0,) * 6
        self.q_cmd = np.asarray(self.q_actual)
        self._motion: _Motion | None = None
        self.freedrive = Freedrive(kin, dt, tcp)
        self.watch: CollisionWatch | None = None  # set by the cell: no watch, no stops
        self.stopped: ProtectiveStop | None = None
        self._unlocks: list[tuple[CommandHandle, float]] = []  # (handle, unlock delay)
        self._command(self.q_cmd, np.zeros(6))

    @property
    def busy(self) -> bool:
        """True while a move or a stop is under way."""
        return self._motion is not None

    @property
    def has_work(self) -> bool:
        """True while the arm may act by itself: a move or stop, freedrive, a protective stop
        or its unlock under way (the physics thread does not rest meanwhile).
        """
        return (
            self._motion is not None
            or self.freedrive.active
            or self.stopped is not None
            or bool(self._unlocks)
        )

    # ---------------------------------------------------------------- commands (physics thread)

    def start_joint_move(
        self, handle: CommandHandle, q: np.ndarray, speed: float, accel: float
    ) -> None:
        """Begin a moveJ from the commanded joints to ``q``."""
        if self._refuse(handle):
            return
        self._begin(_Motion(JointTrajectory(self.q_cmd, q, speed, accel), handle))

    def start_linear_move(
        self, handle: CommandHandle, target: np.ndarray, speed: float, accel: float
    ) -> None:
        """Begin a moveL of the TCP to the world matrix ``target``."""
        if self._refuse(handle):
            return
        try:
            traj = plan_linear(self._kin, self.q_cmd, self._tcp(), target, speed, accel, self._dt)
        except LinearPathError as exc:
            handle.resolve(False, str(exc))
            return
        self._begin(_Motion(traj, handle))

    def stop(self, handle: CommandHandle | None, decel: float, reason: str = "stopped") -> None:
        """Decelerate the current move to a halt; ``handle`` finishes when the arm stands."""
        motion = self._motion
        if motion is None:
            if handle is not None:
                handle.resolve(True, "not moving")
            return
        if handle is not None:
            motion.stop_handles.append(handle)
        if motion.stop_step > 0:
            return
        motion.stop_reason = reason
        _, qd = motion.trajectory.sample(motion.elapsed)
        speed = float(np.max(np.abs(qd))) * motion.rate
        stop_time = min(speed / max(decel, 1e-6), _MAX_STOP_TIME)
        motion.stop_step = motion.rate * self._dt / max(stop_time, self._dt)

    def cancel(self, handle: CommandHandle) -> None:
        """Stop the move of ``handle`` if it is the current one."""
        if self._motion is not None and self._motion.handle is handle:
            self.stop(None, 4.0, f"{handle.name} cancelled")
        else:
            handle.resolve(False, f"{handle.name} cancelled")

    # ---------------------------------------------------------------- protective stop

    def unlock(self, now: float, delay: float) -> str:
        """Unlock a protective stop; a refusal in words ("" when unlocked or not stopped).

        Like PolyScope, it refuses earlier than ``delay`` s after the stop happened.
        """
        stop = self.stopped
        if stop is None:
            return ""
        if now - stop.time < delay:
            return (
                f"cannot unlock the protective stop until {delay:g} s after it happened "
                f"({delay - (now - stop.time):.1f} s left)"
            )
        self.stopped = None
        if self.watch is not None:
            self.watch.leave_contacts()
        self.q_cmd = np.asarray(self.q_actual)
        self._command(self.q_cmd, np.zeros(6))
        return ""

    def clear_when_allowed(self, handle: CommandHandle, delay: float) -> None:
        """Unlock a protective stop as soon as ``delay`` allows; ``handle`` finishes then."""
        if self.stopped is None:
            handle.resolve(True, "not stopped")
        else:
            self._unlocks.append((handle, delay))

    def _watch_safety(self, now: float) -> None:
        if self.stopped is not None:
            for handle, delay in list(self._unlocks):
                if handle.cancel_requested:
                    self._unlocks.remove((handle, delay))
                    handle.resolve(False, f"{handle.name} cancelled")
                elif not self.unlock(now, delay):
                    self._unlocks.remove((handle, delay))
                    handle.resolve(True, "unlocked")
            return
        for handle, _ in self._unlocks:
            handle.resolve(True, "unlocked")
        self._unlocks.clear()
        if self.watch is None or self.freedrive.active:
            return  # in freedrive the hand, not the controller, pushes the arm
        cause = self.watch.check()
        if cause:
            self._protective_stop(ProtectiveStop(now, cause))

    def _protective_stop(self, stop: ProtectiveStop) -> None:
        """Hold where the arm is now and fail the move (the stop is visible before that)."""
        self.stopped = stop
        motion, self._motion = self._motion, None
        self.q_cmd = np.asarray(self.q_actual)
        self._command(self.q_cmd, np.zeros(6))
        if motion is not None:
            motion.handle.resolve(False, stop.message(motion.handle.name))
            for stop_handle in motion.stop_handles:
                stop_handle.resolve(True, "stopped")

    def set_freedrive(self, on: bool) -> None:
        """Enter or leave freedrive; entering halts any move at once."""
        if on:
            if self._motion is not None:
                self._finish_motion(False, "interrupted by freedrive")
            self.q_cmd = np.asarray(self.q_actual)
            self.freedrive.start(self.q_cmd)
        else:
            self.freedrive.stop()
            self.q_cmd = np.asarray(self.q_actual)  # hold where the hand left it
            self._command(self.q_cmd, np.zeros(6))

    def shutdown(self, message: str) -> None:
        """Fail every unfinished handle (the physics thread has ended)."""
        motion, self._motion = self._motion, None
        if motion is not None:
            motion.handle.resolve(False, message)
            for handle in motion.stop_handles:
                handle.resolve(False, message)
        for handle, _ in self._unlocks:
            handle.resolve(False, message)
        self._unlocks.clear()
        self.freedrive.stop()

    # ---------------------------------------------------------------- stepping

    def pre_step(self, _t: float) -> None:
        """Send this step's motor targets."""
        if self.freedrive.active:
            self.q_cmd, qd = self.freedrive.step(self.q_cmd, np.asarray(self.q_actual))
            self._command(self.q_cmd, qd)
            return
        motion = self._motion
        if motion is None:
            return
        if motion.stop_step > 0:
            motion.rate = max(0.0, motion.rate - motion.stop_step)
        motion.elapsed += self._dt * motion.rate
        q, qd = motion.trajectory.sample(motion.elapsed)
        self.q_cmd = q
        self._command(q, qd * motion.rate)

    def post_step(self, _t: float) -> None:
        """Read the joints and finish moves that have arrived or stopped."""
        states = pybullet.getJointStates(self._body, self._joints, physicsClientId=self._client)
        self.q_actual = tuple(s[0] for s in states)
        self.qd_actual = tuple(s[1] for s in states)
        self._watch_safety(_t)
        motion = self._motion
        if motion is None:
            return
        if motion.stop_step > 0 and motion.rate <= 0.0:
            self._finish_motion(False, motion.stop_reason)
            return
        if motion.elapsed >= motion.trajectory.duration:
            self._settle(motion)

    # ---------------------------------------------------------------- internals

    def _refuse(self, handle: CommandHandle) -> bool:
        if handle.cancel_requested:
            handle.resolve(False, f"{handle.name} cancelled")
            return True
        if self.stopped is not None:
            handle.resolve(False, self.stopped.message(handle.name))
            return True
        if self.freedrive.active:
            handle.resolve(False, f"{handle.name} refused: freedrive is active")
            return True
        return False

    def _begin(self, motion: _Motion) -> None:
        if self._motion is not None:
            # A new move replaces the running one, like a new command on a UR controller.
            self._finish_motion(False, f"preempted by {motion.handle.name}")
        self._motion = motion

    def _settle(self, motion: _Motion) -> None:
        motion.settle += self._dt
        error = float(np.max(np.abs(np.asarray(self.q_actual) - self.q_cmd)))
        # Ended as a UR's moves end: on the target and standing still.
        if error < _SETTLED_RAD and max(abs(v) for v in self.qd_actual) < MOVING_SPEED:
            self._finish_motion(True, "reached")
        elif motion.settle >= _SETTLE_TIMEOUT:
            ok, message = self._arrival_check()
            # Held back short of the target (blocked by contact): hold where the arm stopped.
            # Holding the unreached target would keep it pressing with its full joint torques
            # on whatever holds it back, and the arm would creep as that gives way.
            self._finish_motion(ok, message, hold=None if ok else np.asarray(self.q_actual))

    def _arrival_check(self) -> tuple[bool, str]:
        tcp = self._tcp()
        want = self._kin.tcp_matrix(self.q_cmd, tcp)
        have = self._kin.tcp_matrix(self.q_actual, tcp)
        dist = float(np.linalg.norm(want[:3, 3] - have[:3, 3]))
        angle = rotation_angle(want[:3, :3].T @ have[:3, :3])
        if dist <= _TOL_M and angle <= _TOL_RAD:
            return True, "reached"
        return False, (
            f"blocked: the TCP stopped {dist * 1000:.1f} mm and {math.degrees(angle):.2f} deg "
            "from the target (a collision?)"
        )

    def _finish_motion(self, ok: bool, message: str, hold: np.ndarray | None = None) -> None:
        """End the current move; the arm then holds ``hold`` (joints), by default where the
        trajectory is now (a stopped move stays on its path).
        """
        motion = self._motion
        self._motion = None
        if motion is None:
            return
        if hold is not None:
            self.q_cmd = hold
        elif not ok:
            self.q_cmd = motion.trajectory.sample(motion.elapsed)[0]
        self._command(self.q_cmd, np.zeros(6))
        motion.handle.resolve(ok, message)
        for stop_handle in motion.stop_handles:
            stop_handle.resolve(True, "stopped")

    def _command(self, q: np.ndarray, qd: np.ndarray) -> None:
        pybullet.setJointMotorControlArray(
            self._body,
            self._joints,
            pybullet.POSITION_CONTROL,
            targetPositions=[float(v) for v in q],
            targetVelocities=[float(v) for v in qd],
            forces=_FORCES,
            positionGains=[_POSITION_GAIN] * 6,
            velocityGains=[_VELOCITY_GAIN] * 6,
            physicsClientId=self._client,
        )
