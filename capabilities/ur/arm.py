"""The UR arm as the motion and freedrive capabilities see it (ArmBackend, FreedriveBackend).

Moves are ur_rtde's asynchronous moveJ/moveL; a monitor on the connection's I/O thread
finishes the handle when the controller reports the asynchronous operation done, fails it on a
protective or emergency stop, power off, a dead control script or a lost connection, and stops
the arm (stopJ/stopL) when the handle is cancelled. Poses cross into UR terms (base frame,
rotation vectors) here and nowhere else.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from capabilities.faults import PROTECTIVE_STOP
from capabilities.robot.commands import CommandHandle
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.ur.connection import (
    HALT_DECEL,
    NO_SCRIPT,
    SCRIPT_END_GRACE,
    URConnection,
    URState,
    fault_reason,
)
from capabilities.ur.errors import URError, ur_words
from capabilities.ur.frames import URFrames
from capabilities.ur.modes import PolyScopeVersion, RobotMode
from engine.types import Pose

__all__ = ["URArm", "FREEDRIVE_MODE_SINCE", "require_version"]

FREEDRIVE_MODE_SINCE: PolyScopeVersion = (5, 10)
_JOINT_TOLERANCE = 0.01  # rad: a finished move this far from its target did not arrive
_POSITION_TOLERANCE = 0.002  # m
# s a stopped script must last before it is the reason: a dropping connection first looks
# like one, and a protective stop's safety mode can come a few frames after the script's end.
# It outlasts the hold's own wait (SCRIPT_END_GRACE) so that the run is held before the
# move fails: a script that ended for good holds the run rather than failing its node.
_SCRIPT_GRACE = SCRIPT_END_GRACE + 0.2
_START_TIMEOUT = 2.0  # s for the controller to report the asynchronous move started
_CLEAR_TIMEOUT = 20.0  # s for a protective stop to be unlocked and the script to run again
_UNLOCK_RETRY = 0.5  # s between unlock attempts the controller refused (too early)


def require_version(connection: URConnection, operation: str, needed: PolyScopeVersion) -> None:
    """Raise unless the controller runs at least ``needed``.

    Raises:
        URError: naming the operation, the version it needs and the one the robot runs.
    """
    if connection.version < needed:
        have = ".".join(map(str, connection.version))
        raise URError(
            f"{operation} needs PolyScope {needed[0]}.{needed[1]} or newer; "
            f"the controller runs {have}"
        )


class URArm:
    """A UR5 through ur_rtde: state, kinematics, moves, stop, speed slider and freedrive.

    Args:
        connection: the open connection (its I/O thread runs every ur_rtde call).
        base: world pose of the UR base frame.
        tcp: the TCP in the flange frame (also set on the controller).
        home: home joints (rad).
    """

    def __init__(
        self, connection: URConnection, base: Pose, tcp: Pose, home: Sequence[float]
    ) -> None:
        self._conn = connection
        self.frames = URFrames(base)
        self._tcp = tcp
        self._kin = UR5Kinematics(base)
        self._home = tuple(float(v) for v in home)
        self._freedrive = False

    # ---------------------------------------------------------------- state

    def _readable(self) -> URState:
        state = self._conn.state
        if not state.connected:
            raise URError(f"no pose: {fault_reason(state)}")
        if state.robot_mode < RobotMode.RUNNING:
            raise URError(
                f"no pose: the arm is not running (robot mode {RobotMode(state.robot_mode).name})"
            )
        return state

    def joint_positions(self) -> tuple[float, ...]:
        """Measured joints (rad); raises URError while the arm is not running."""
        return self._readable().q

    def tcp_pose(self) -> Pose:
        """World pose of the TCP; raises URError while the arm is not running."""
        return self.frames.from_ur(self._readable().tcp)

    def is_moving(self) -> bool:
        return self._conn.state.moving

    def home_joints(self) -> tuple[float, ...]:
        return self._home

    def inverse_kinematics(
        self, pose: Pose, near: Sequence[float] | None = None
    ) -> tuple[float, ...] | None:
        return self._kin.inverse(
            pose, near if near is not None else self.joint_positions(), self._tcp
        )

    # ---------------------------------------------------------------- moves

    def move_joints(
        self, q: Sequence[float], speed: float = 1.05, accel: float = 1.4
    ) -> CommandHandle:
        target = [float(v) for v in q]
        if len(target) != 6 or not all(math.isfinite(v) for v in target):
            return CommandHandle.failed("move_joints", f"moveJ needs 6 finite joints, got {target}")
        return self._move(
            "move_joints",
            lambda c: c.moveJ(target, speed, accel, True),
            "stopJ",
            lambda s: (
                max(abs(a - b) for a, b in zip(s.q, target, strict=False)) <= _JOINT_TOLERANCE
            ),
        )

    def move_linear(self, pose: Pose, speed: float = 0.25, accel: float = 1.2) -> CommandHandle:
        target = self.frames.to_ur(pose)
        return self._move(
            "move_linear",
            lambda c: c.moveL(target, speed, accel, True),
            "stopL",
            lambda s: math.dist(s.tcp[:3], target[:3]) <= _POSITION_TOLERANCE,
        )

    def move_pose_joint_space(
        self, pose: Pose, speed: float = 1.05, accel: float = 1.4
    ) -> CommandHandle:
        try:
            q = self.inverse_kinematics(pose)
        except URError as exc:
            return CommandHandle.failed("move_pose_joint_space", str(exc))
        if q is None:
            return CommandHandle.failed("move_pose_joint_space", "unreachable pose")
        return self.move_joints(q, speed, accel)

    def stop(self, decel: float = HALT_DECEL) -> CommandHandle:
        handle = CommandHandle("stop")

        def run() -> None:
            if self._conn.control is not None and self._conn.state.program_running:
                self._conn.control.stopJ(decel)
            handle.resolve(True, "stopped")

        self._submit(handle, run)
        return handle

    def clear_protective_stop(self, timeout: float = _CLEAR_TIMEOUT) -> CommandHandle:
        """Unlock a protective stop through the dashboard as soon as the controller allows
        it (5 s after the stop on a UR), and finish when the arm runs again (the control
        script uploaded again). At once when the arm can move. It fails with the fault's
        words on what only the operator may clear (an emergency stop, power off, a lost
        connection), and with "timed out" after ``timeout`` s.
        """
        handle = CommandHandle("clear_protective_stop", lambda h: None)  # the monitor sees it
        unlock = _Unlock(handle, time.monotonic() + timeout)
        self._submit(handle, lambda: self._conn.add_monitor(unlock))
        return handle

    def set_speed_fraction(self, fraction: float) -> CommandHandle:
        """The speed slider (0..1) through RTDEIO."""
        handle = CommandHandle("set_speed_fraction")
        if not 0.0 <= fraction <= 1.0:
            handle.resolve(False, f"speed fraction must be within 0..1, got {fraction}")
            return handle

        def run() -> None:
            ok = self._conn.with_io(lambda io: io.setSpeedSlider(float(fraction)))
            handle.resolve(bool(ok), "" if ok else "setSpeedSlider refused")

        self._submit(handle, run)
        return handle

    def _submit(self, handle: CommandHandle, run: Callable[[], None]) -> None:
        def fail(future: Future[None]) -> None:
            exc = future.exception()
            if exc is not None:
                handle.resolve(False, f"{handle.name}: {_lost(exc, self._conn)}")

        self._conn.submit(run).add_done_callback(fail)

    def _move(
        self,
        name: str,
        send: Callable[[Any], bool],
        stop_name: str,
        arrived: Callable[[URState], bool],
    ) -> CommandHandle:
        handle = CommandHandle(name, lambda h: None)  # cancel is seen by the monitor
        conn = self._conn
        deadline = time.monotonic() + _START_TIMEOUT

        def send_now() -> None:
            problem = fault_reason(conn.state)
            if problem:
                handle.resolve(False, f"{name}: {problem}")
                return
            before = conn.state.async_op_id
            if not send(conn.control):
                conn.refresh()
                handle.resolve(
                    False, f"{name}: {fault_reason(conn.state) or 'refused by the controller'}"
                )
                return
            _Monitor(handle, before, stop_name, arrived).attach(conn)

        def send_when_idle(c: URConnection) -> bool:
            """A halted move's asynchronous stop may still decelerate the arm: its end would
            end this move too (and look like it), so this one waits for it (bounded).
            """
            if handle.done():
                return True
            if handle.cancel_requested:
                handle.resolve(False, f"{name} halted")
                return True
            if c.state.async_running and time.monotonic() < deadline:
                return False
            send_now()
            return True

        def start() -> None:
            if not send_when_idle(conn):
                conn.add_monitor(send_when_idle)

        self._submit(handle, start)
        return handle

    # ---------------------------------------------------------------- freedrive

    def set_freedrive(self, on: bool) -> None:
        """Hand guiding: freedriveMode on PolyScope 5.10 and later, teachMode before.

        Blocks for the controller's answer (call it off the engine thread).

        Raises:
            URError: the controller refused, or the robot cannot be hand guided now.
        """

        def run() -> None:
            control = self._conn.control
            problem = fault_reason(self._conn.state)
            if problem:
                raise URError(f"freedrive: {problem}")
            new = self._conn.version >= FREEDRIVE_MODE_SINCE
            if on:
                ok = control.freedriveMode() if new else control.teachMode()
            else:
                ok = control.endFreedriveMode() if new else control.endTeachMode()
            if not ok:
                verb = (
                    ("freedriveMode" if on else "endFreedriveMode")
                    if new
                    else ("teachMode" if on else "endTeachMode")
                )
                raise URError(f"freedrive: {verb} refused: {fault_reason(self._conn.state)}")
            self._freedrive = on

        self._conn.call(run)

    def freedrive_active(self) -> bool:
        return self._freedrive

    def freedrive_status(self) -> int:
        """GetFreedriveStatus (PolyScope 5.10 and later). Blocks for the answer.

        Raises:
            URError: an older controller (the message names the version needed).
        """
        require_version(self._conn, "freedrive status (getFreedriveStatus)", FREEDRIVE_MODE_SINCE)
        return int(self._conn.call(lambda: self._conn.control.getFreedriveStatus()))


def _lost(exc: BaseException, conn: URConnection) -> str:
    if isinstance(exc, URError):
        return str(exc)
    conn.refresh()
    reason = fault_reason(conn.state)
    return reason if reason.startswith("connection lost") else f"connection lost ({ur_words(exc)})"


@dataclass(eq=False)  # by identity: the connection drops it from its list of monitors
class _Monitor:
    """Watches one asynchronous move on the I/O thread."""

    handle: CommandHandle
    op_before: int
    stop_name: str
    arrived: Callable[[URState], bool]
    started: bool = False
    deadline: float = 0.0
    script_gone_at: float | None = None
    script_run: int = -1  # the connection's script_runs when the move was sent

    def _debounce(self, now: float) -> bool:
        """True while a stopped script has been seen for less than the grace time."""
        if self.script_gone_at is None:
            self.script_gone_at = now
        return now - self.script_gone_at < _SCRIPT_GRACE

    def attach(self, conn: URConnection) -> None:
        self.deadline = time.monotonic() + _START_TIMEOUT
        self.script_run = conn.script_runs
        conn.add_monitor(self)

    def __call__(self, conn: URConnection) -> bool:
        handle, state = self.handle, conn.state
        if handle.done():
            return True
        if conn.script_runs != self.script_run:
            # The script that ran this move ended and another runs now: the move ended with
            # it, and a stop sent now would end the new script's move instead.
            handle.resolve(False, f"{handle.name}: {NO_SCRIPT}")
            return True
        problem = fault_reason(state)
        if problem == NO_SCRIPT and self._debounce(time.monotonic()):
            return False  # a dropping connection first looks like a stopped script
        if problem:
            handle.resolve(False, f"{handle.name}: {problem}")
            return True
        self.script_gone_at = None
        if handle.cancel_requested:
            try:
                getattr(conn.control, self.stop_name)(HALT_DECEL, True)
            finally:
                handle.resolve(False, f"{handle.name} halted")
            return True
        if state.async_op_id != self.op_before:
            self.started = True
        if self.started and not state.async_running:
            if self.arrived(state):
                handle.resolve(True)
            else:
                handle.resolve(False, f"{handle.name}: the move ended away from its target")
            return True
        if not self.started and time.monotonic() > self.deadline:
            handle.resolve(False, f"{handle.name}: the controller did not start the move")
            return True
        return False


class _Unlock:
    """(I/O thread) Unlocks a protective stop and waits until the arm can move again."""

    def __init__(self, handle: CommandHandle, deadline: float) -> None:
        self.handle = handle
        self.deadline = deadline
        self.next_try = 0.0
        self.refused = ""

    def __call__(self, conn: URConnection) -> bool:
        handle, now = self.handle, time.monotonic()
        problem = fault_reason(conn.state)
        if handle.cancel_requested:
            handle.resolve(False, f"{handle.name} cancelled")
        elif not problem:
            handle.resolve(True, "the arm can move")
        elif now > self.deadline:
            why = f" (the controller said: {self.refused})" if self.refused else ""
            handle.resolve(False, f"{handle.name}: timed out{why}")
        elif problem == PROTECTIVE_STOP:
            if now >= self.next_try:
                self.next_try = now + _UNLOCK_RETRY
                try:
                    conn.clear_protective_stop()  # unlock, then upload the script again
                except Exception as exc:  # too early after the stop: the controller refuses
                    self.refused = ur_words(exc)
            return False
        elif problem == NO_SCRIPT:
            return False  # unlocked: the script is on its way (or the recovery monitor's)
        else:  # an emergency stop, power off, a lost connection: the operator's to clear
            handle.resolve(False, f"{handle.name}: {problem} (for the operator to clear)")
        return handle.done()


if TYPE_CHECKING:  # the arm is both interfaces the capabilities ask a cell for
    from capabilities.freedrive.backend import FreedriveBackend
    from capabilities.motion.backend import ArmBackend

    def _conforms(arm: URArm) -> tuple[ArmBackend, FreedriveBackend]:
        return arm, arm
