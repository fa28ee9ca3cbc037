"""A real UR cell as capabilities see it: the arm, its tool, and what the operator clears.

``interfaces()`` gives ``arm`` and ``freedrive`` (the URArm), the tool (``suction``, a cup on
a digital output, or ``gripper``, a Robotiq gripper through its URCap), ``rgbd:<name>`` (the cell file's cameras whose source is recorded frames or a RealSense: a
real cell renders nothing), ``world``, ``workers``, ``objects`` (the cell file's object library),
``scene_layout`` (marker sizes of the library) and ``operator``. :meth:`URCellSession.
hold_reason` is the executor's hold check: it names a protective stop, an emergency stop, power
off, a lost connection or a dead control script in words, so the run is held within one tick.
Digital inputs named in the cell file (``inputs.pedal``) press the operator console's
"continue" button on each rising edge, and releasing the pendant's teach button (after guiding
the arm by hand) presses its "teach" button, so a plan waits for either with
``collaboration.wait_for_button`` and records the waypoint with ``freedrive.record_waypoint``.
A recovery monitor on the connection's I/O thread does the robot side of clearing it: once the
operator has unlocked the stop (or released the button and powered on), it uploads the control
script again, and it reconnects when the socket is really gone. A script that ended with no
stop (stopped on the pendant, a script error) is uploaded again only on the operator's
:meth:`URCellSession.clear`. Then the hold clears and the run
goes on from the node that was running.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping
from concurrent.futures import Future
from typing import Any

from capabilities.camera_source import CameraSource
from capabilities.camera_sources import open_source
from capabilities.cell_features import CellStatus, ClosesOnExit
from capabilities.collaboration.console import OperatorConsole
from capabilities.collaboration.inputs import DigitalInputButton
from capabilities.faults import CONNECTION_LOST, PROTECTIVE_STOP
from capabilities.jobs import WorkerPool
from capabilities.object_library import ObjectLibrary
from capabilities.robot.cell_file import CellConfig
from capabilities.robot.cell_robot import TCP_OF_TOOL, UNLOCK_DELAY
from capabilities.ur.arm import URArm
from capabilities.ur.connection import NO_SCRIPT, TAKEN_OVER, URConnection, fault_reason
from capabilities.ur.errors import ur_words
from capabilities.ur.frames import URFrames
from capabilities.ur.modes import RobotMode, SafetyMode
from capabilities.ur.robotiq import RobotiqGripper
from capabilities.ur.tool_io import (
    DigitalPin,
    TeachButtonReleased,
    URDigitalInput,
    URSuctionCup,
)
from capabilities.world_model import WorldModel
from engine.types import Pose

__all__ = ["TEACH_BUTTON", "URCellSession"]

_log = logging.getLogger(__name__)
TEACH_BUTTON = "teach"  # the console button the pendant's teach button presses on release
_RETRY_SCRIPT = 1.0  # s between uploads of the control script while it is not running
_RETRY_CONNECT = 2.0  # s between reconnection attempts
_LET_UR_RTDE_TRY = 5.0  # s of a lost connection before ours (see _Recovery)
# s after this program resumed from a stall longer than the watchdog's period in which a
# script seen stopped is the watchdog's doing (it is seen at the first refresh after it).
_STALL_WINDOW = 0.25
_REARM_AFTER = 1.0  # s of a robot that can move before an unarmed watchdog is set again
WATCHDOG_STOP = (
    "the arm stopped: this program did not answer the controller in time (its watchdog); "
    "the control script is started again"
)
RESTART_SCRIPT = "Restart control script"  # the status bar's clear of a stopped script
UNLOCK_STOP = "Unlock protective stop"  # the status bar's clear of a protective stop
# A UR refuses to unlock a protective stop earlier than this after it (PolyScope's rule).
STOP_UNLOCK_DELAY = UNLOCK_DELAY


class URCellSession(ClosesOnExit):
    """A UR controller at the cell file's host; a context manager.

    Args:
        config: the cell file (its ``robot`` block has kind "ur").
        connect_timeout: seconds to wait for the controller at start.

    Raises:
        URConnectionLost: the controller does not answer.
    """

    name = "ur"

    def __init__(self, config: CellConfig, connect_timeout: float = 30.0) -> None:
        robot = config.robot
        self.config = config
        tool_tcp = config.tcp_offsets.get(TCP_OF_TOOL[robot.tool.kind], Pose())
        self.connection = URConnection(
            robot.host,
            tcp=URFrames(Pose()).to_ur(tool_tcp),
            payload=(robot.payload.mass, robot.payload.center_of_gravity),
        )
        self.world_model = WorldModel()
        self.workers = WorkerPool(2, "costar-ur-worker")
        self.operator = OperatorConsole(("continue", TEACH_BUTTON))
        self._buttons: list[DigitalInputButton] = []
        self.library = ObjectLibrary(config.objects_path())
        try:
            self.connection.open(connect_timeout)
        except BaseException:
            self.workers.close()
            raise
        self.arm = URArm(self.connection, config.robot_base, tool_tcp, config.home_joints)
        self.tool: dict[str, Any] = {}
        self.cameras: dict[str, CameraSource] = {}
        try:
            self.tool = self._tool()
            self.cameras = {
                name: open_source(name, c.source, c.where, config.folder())
                for name, c in config.cameras.items()
                if c.source != "sim"
            }
        except BaseException:
            self.close()
            raise
        self._recovery = _Recovery()
        self.connection.watch(self._recovery)
        self._start_buttons()

    def _start_buttons(self) -> None:
        """The pendant's teach button and the pedal press the operator console's buttons."""
        teach = TeachButtonReleased(self.connection)
        self._buttons = [DigitalInputButton(teach, self.operator, TEACH_BUTTON)]
        pedal_pin = self.config.robot.inputs.get("pedal")
        if pedal_pin is not None:
            pedal = URDigitalInput(self.connection, DigitalPin(*pedal_pin))
            self._buttons.append(DigitalInputButton(pedal, self.operator, "continue"))
        for button in self._buttons:
            button.start()

    def _tool(self) -> dict[str, Any]:
        tool = self.config.robot.tool
        if tool.kind == "robotiq":
            return {"gripper": RobotiqGripper(self.connection)}
        sensor = DigitalPin(*tool.sensor) if tool.sensor else None
        return {"suction": URSuctionCup(self.connection, DigitalPin(*tool.vacuum), sensor)}

    # ---------------------------------------------------------------- what capabilities use

    def interfaces(self) -> Mapping[str, Any]:
        return {
            "arm": self.arm,
            "freedrive": self.arm,
            **self.tool,
            **{f"rgbd:{name}": camera for name, camera in self.cameras.items()},
            "world": self.world_model,
            "workers": self.workers,
            "objects": self.library,
            "scene_layout": self.scene_layout(),
            "operator": self.operator,
        }

    def scene_layout(self) -> dict[str, Any]:
        """Marker sizes of every model in the object library (no fixed markers known)."""
        sizes: dict[int, float] = {}
        for name in self.library.names():
            sizes.update({m.marker_id: m.size for m in self.library.get(name).markers})
        return {"marker_sizes": sizes, "fixed_markers": {}}

    def clock(self) -> float:
        return time.monotonic()

    def capability_settings(self) -> tuple[Mapping[str, Any], str]:
        return self.config.capabilities, self.config.source or "the UR cell's file"

    # ---------------------------------------------------------------- safety

    def hold_reason(self) -> str:
        """Why the robot cannot act now, in words ("" when it can): the executor's hold check.

        Reads the snapshot the I/O thread keeps: never a call into ur_rtde. A stop lasts
        until the arm runs again: between the unlock of a protective stop and the control
        script's upload it still reads "protective stop" (not a new fault of its own).
        """
        reason = self.connection.fault()
        if reason == NO_SCRIPT and self._recovery.clearing:
            return self._recovery.clearing
        # A script's end that a protective stop's safety mode follows within a few frames
        # is that stop only: no "script not running" in between (the arm stands either way).
        return self.connection.settled_fault() if reason == NO_SCRIPT else reason

    def clear(self) -> None:
        """The operator's clear of what the status names: unlock a protective stop (through
        the dashboard, as the pendant's Unlock does; the control script is uploaded again),
        or upload again a control script that ended on its own (stopped on the pendant, a
        script error). Returns at once (the I/O thread does it); the hold lifts when the
        script runs. A refused unlock (too early) goes to the log; the stop stays shown.
        """
        if self.connection.fault() == PROTECTIVE_STOP:
            future = self.connection.submit(self.connection.clear_protective_stop)
        else:
            future = self.connection.submit(self.connection.start_control)
        future.add_done_callback(_log_refusal)

    def clear_protective_stop(self) -> None:
        """Unlock a protective stop through the dashboard and upload the control script
        again (blocks for the controller's answer; never from the engine thread).

        Raises:
            URError: the controller refused (too early after the stop, or another fault).
        """
        self.connection.call(self.connection.clear_protective_stop)

    def status(self) -> CellStatus:
        """The robot's state for the toolbar (a snapshot; never blocks)."""
        state, fault = self.connection.state, self.connection.settled_fault()
        if not state.connected or fault.startswith(CONNECTION_LOST):
            return CellStatus(False, "DISCONNECTED", "-", "-", fault + _last_heard(self.connection))
        action, wait, hint = "", 0, ""
        if fault == NO_SCRIPT:
            action = RESTART_SCRIPT
            hint = f"start it on the pendant or press {RESTART_SCRIPT}"
        elif fault == TAKEN_OVER:
            action = RESTART_SCRIPT
            hint = f"end the other program (or close that client), then press {RESTART_SCRIPT}"
        elif fault == PROTECTIVE_STOP:
            action = UNLOCK_STOP
            since = self._recovery.stopped_at
            left = STOP_UNLOCK_DELAY - (time.monotonic() - since if since is not None else 0.0)
            wait = max(0, math.ceil(left))
            hint = f"clear it on the pendant or press {UNLOCK_STOP}"
        return CellStatus(
            True,
            RobotMode(state.robot_mode).name,
            SafetyMode(state.safety_mode).name,
            "PLAYING" if state.program_running else "STOPPED",
            fault,
            action,
            wait,
            hint,
        )

    # ---------------------------------------------------------------- lifetime

    def close(self) -> None:
        for button in self._buttons:
            button.stop()
        self.connection.close()
        self.workers.close()


def _log_refusal(future: Future[None]) -> None:
    """The operator's clear failed (a refused unlock): say so in the log."""
    exc = future.exception()
    if exc is not None:
        _log.warning("UR: the operator's clear failed: %s", ur_words(exc))


def _last_heard(connection: URConnection) -> str:
    """What was last heard of the robot, as a suffix of a fault; "" when nothing was.

    For example "; last heard 12 s ago: robot mode RUNNING, safety mode NORMAL, program running".
    """
    last = connection.last_heard
    if not last.stamp:
        return ""
    program = "running" if last.program_running else "stopped"
    return (
        f"; last heard {time.monotonic() - last.stamp:.0f} s ago: robot mode "
        f"{RobotMode(last.robot_mode).name}, safety mode {SafetyMode(last.safety_mode).name}, "
        f"program {program}"
    )


class _Recovery:
    """(I/O thread) The robot side of clearing a fault, polled every cycle, never finished.

    The operator clears the cause (unlocks a protective stop, releases an emergency stop and
    powers on, restores the network); this then uploads the control script again once the
    robot is running in normal safety, and reconnects when the connection is gone.
    """

    def __init__(self) -> None:
        self._next_try = 0.0
        self._lost_since: float | None = None
        self._well_since: float | None = None  # the robot can move, the watchdog unarmed
        self.clearing = ""  # the stop or power loss being cleared ("" when none)
        self.stopped_at: float | None = None  # when the protective stop under way was seen

    def __call__(self, conn: URConnection) -> bool:
        now = time.monotonic()
        state = conn.state
        if state.connected:
            self._lost_since = None
        elif self._lost_since is None:
            self._lost_since = now
        problem = fault_reason(state)
        self._time_stop(problem, now)
        if problem and problem not in (NO_SCRIPT, TAKEN_OVER):
            self.clearing = problem  # (another client's program is the operator's to end)
        elif not problem:
            self.clearing = ""
        elif not self.clearing and now - conn.stalled_at < _STALL_WINDOW:
            # The script's watchdog stopped it (and the arm) while this process was stalled;
            # it answers again, so it is not dead: start the script again, as after a stop.
            self.clearing = WATCHDOG_STOP
            _log.warning("UR: %s", WATCHDOG_STOP)
        self._rearm_watchdog(conn, now, problem)
        if now < self._next_try:
            return False
        try:
            if not state.connected:
                # ur_rtde's control interface first tries to reconnect on its own thread;
                # disconnecting it while it does crashes the process: let it finish first.
                if now - (self._lost_since or now) < _LET_UR_RTDE_TRY:
                    return False
                self._next_try = now + _RETRY_CONNECT
                conn.reconnect()
            elif problem == NO_SCRIPT and self.clearing:
                # The operator cleared a stop (the script ends with it): upload it again. A
                # script that ended on its own (stopped on the pendant, a script error) waits
                # for the operator's clear() instead.
                self._next_try = now + _RETRY_SCRIPT
                conn.start_control()
        except Exception as exc:  # the controller is not back yet: try again later
            _log.debug("UR recovery: %s", exc)
        return False

    def _time_stop(self, problem: str, now: float) -> None:
        """Note when a protective stop was first seen (the unlock's delay counts from it)."""
        if problem != PROTECTIVE_STOP:
            self.stopped_at = None
        elif self.stopped_at is None:
            self.stopped_at = now

    def _rearm_watchdog(self, conn: URConnection, now: float, problem: str) -> None:
        """A connection that came back by ur_rtde's own reconnect, with its script running
        on, has no watchdog kicked (kicks stop while it is away): set it again once all has
        been well for a moment (ur_rtde's reconnect has then finished).
        """
        if problem or conn.watchdog_armed:
            self._well_since = None
        elif self._well_since is None:
            self._well_since = now
        elif now - self._well_since > _REARM_AFTER:
            self._well_since = None
            try:
                conn.arm_watchdog()
            except Exception as exc:  # gone again: the next quiet moment tries again
                _log.debug("UR recovery: arming the watchdog: %s", exc)
