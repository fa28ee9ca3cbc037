"""The connection to a UR controller through ur_rtde, on its own I/O thread.

Every ur_rtde call runs on the thread this class starts; callers queue work with
:meth:`URConnection.submit` (a Future) or :meth:`URConnection.watch` (a monitor polled every
cycle) and read :attr:`URConnection.state`, a snapshot the thread refreshes each cycle. The
engine's and the GUI's threads never wait on the robot.

Stop means stop. A UR goes on with its last move when the program that sent it dies, so:
closing the connection (also at interpreter exit) first decelerates the arm to a halt and
ends the control script, on the I/O thread, before anything is disconnected; and the control
script's RTDE watchdog (``setWatchdog``), kicked by the I/O thread every few cycles, stops
the program, and with it the arm, when this process is killed or frozen.
"""

from __future__ import annotations

import atexit
import logging
import queue
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any, TypeVar

from capabilities.faults import CONNECTION_LOST, EMERGENCY_STOP, PROTECTIVE_STOP
from capabilities.ur.errors import URConnectionLost, URError, ur_words
from capabilities.ur.modes import PolyScopeVersion, RobotMode, SafetyMode, parse_version

__all__ = [
    "HALT_DECEL",
    "NO_SCRIPT",
    "SCRIPT_END_GRACE",
    "TAKEN_OVER",
    "URConnection",
    "WATCHDOG_HZ",
    "URState",
    "fault_reason",
]

_log = logging.getLogger(__name__)
T = TypeVar("T")
_EMERGENCY = (SafetyMode.ROBOT_EMERGENCY_STOP, SafetyMode.SYSTEM_EMERGENCY_STOP)
_MOVING_SPEED = 1e-3  # rad/s
# s without a fresh state before the controller's silence is a lost connection: the I/O thread
# can sit inside a ur_rtde call (a move's send) for good when the controller dies under it.
SILENCE_S = 3.0
NO_SCRIPT = "the control script is not running on the controller"
# s a control script's end waits for a safety mode that comes with it: a UR's RTDE streams
# can report the program's end a few frames before the protective stop that ended it.
SCRIPT_END_GRACE = 0.3
# A UR runs one program: another client's (an Instructor, a ur_rtde script) ended ours.
TAKEN_OVER = (
    "another program took the robot: the controller ended this session's control script "
    "for a program this session did not start (another Instructor or ur_rtde client)"
)
# The control script stops the program (and the arm) when no RTDE input arrives for
# 1/WATCHDOG_HZ s: kill -9 or a frozen process halts the arm within 0.2 s plus the stop.
WATCHDOG_HZ = 5.0
_KICK_PERIOD = 0.02  # s between kicks: ten per watchdog period
HALT_DECEL = 4.0  # rad/s^2: the controlled stop when the connection closes (as Stop's)
_HALT_TIMEOUT = 2.0  # s for the arm to stand before the script is ended regardless


@dataclass(frozen=True)
class URState:
    """What the controller reported at the last cycle of the I/O thread."""

    connected: bool = False
    robot_mode: int = int(RobotMode.DISCONNECTED)
    safety_mode: int = int(SafetyMode.NORMAL)
    program_running: bool = False
    q: tuple[float, ...] = (0.0,) * 6
    qd: tuple[float, ...] = (0.0,) * 6
    tcp: tuple[float, ...] = (0.0,) * 6  # UR base frame, [x, y, z, rx, ry, rz]
    digital_outputs: int = 0
    digital_inputs: int = 0
    status_bits: int = 0  # robot_status_bits: 0 power on, 1 program running, 2 teach button
    async_running: bool = False
    async_op_id: int = -1
    taken_over: bool = False  # another client's program ended this session's script
    stamp: float = 0.0
    problem: str = field(default="")

    @property
    def teach_button(self) -> bool:
        """The pendant's teach (freedrive) button is held down."""
        return bool(self.status_bits & 4)

    @property
    def moving(self) -> bool:
        return self.async_running or max(abs(v) for v in self.qd) > _MOVING_SPEED


def fault_reason(state: URState) -> str:
    """Why the robot cannot move now, in words ("" when it can)."""
    if not state.connected:
        return CONNECTION_LOST + (f" ({state.problem})" if state.problem else "")
    safety = SafetyMode(state.safety_mode)
    if safety == SafetyMode.PROTECTIVE_STOP:
        return PROTECTIVE_STOP
    if safety in _EMERGENCY:
        return EMERGENCY_STOP
    if safety not in (SafetyMode.NORMAL, SafetyMode.REDUCED):
        return f"safety stop ({safety.name})"
    if state.robot_mode < RobotMode.RUNNING:
        mode = RobotMode(state.robot_mode).name
        return (
            "the arm is powered off"
            if state.robot_mode <= RobotMode.POWER_OFF
            else (f"the arm is not running (robot mode {mode})")
        )
    if state.taken_over:
        return TAKEN_OVER
    if not state.program_running:
        return NO_SCRIPT
    return ""


Monitor = Callable[["URConnection"], bool]  # True when done (drop it)


class URConnection:
    """ur_rtde's four interfaces to one controller, owned by one I/O thread.

    Args:
        host: the controller's address.
        tcp: the TCP as ``[x, y, z, rx, ry, rz]`` in the flange frame (sent with setTcp).
        rate: state polls per second.
        payload: (mass kg, centre of gravity m in the flange frame), set with setPayload.
    """

    def __init__(
        self,
        host: str,
        tcp: list[float] | None = None,
        rate: float = 125.0,
        payload: tuple[float, Sequence[float]] | None = None,
    ) -> None:
        self.host = host
        self.version: PolyScopeVersion = (0, 0)
        self._tcp = list(tcp) if tcp is not None else [0.0] * 6
        self._payload = payload
        self._period = 1.0 / rate
        self.state = URState()
        self.last_heard = URState()  # the last state read while connected
        self._tasks: queue.Queue[Callable[[], None] | None] = queue.Queue()
        self._monitors: list[Monitor] = []
        self._closing = threading.Event()
        self._thread = threading.Thread(target=self._run, name="costar-ur-io", daemon=True)
        self._watchdog = False  # set on the running control script
        self._last_kick = 0.0  # when the last kick began (kicks are rate-limited by it)
        self._kicked = 0.0  # when the last kick ended
        self._halted = False  # close() halted the arm: no more work runs
        # Counts the control scripts this connection started: a move's monitor never stops
        # the arm through a script other than the one that ran its move.
        self.script_runs = 0
        # Whether the program that runs is this session's script (start_control saw it run):
        # one seen running that this session did not start is another client's.
        self._ours = False
        self._uploading = False
        self.taken_over = False
        self.script_ended_at = -1e9  # when the script was last seen to end (any thread reads)
        # When the I/O thread last resumed after a stall longer than the watchdog's period
        # (another thread held the GIL: an import, a long C call): the script may have
        # stopped on it, which is ours to restart (see capabilities.ur.cell._Recovery).
        self.stalled_at = -1e9
        # ur_rtde objects: touched on the I/O thread only.
        self.dashboard: Any = None
        self.receive: Any = None
        self.control: Any = None

    # ---------------------------------------------------------------- lifecycle

    def open(self, timeout: float = 30.0) -> None:
        """Start the I/O thread and connect (blocks the caller up to ``timeout`` s).

        Raises:
            URConnectionLost: the controller does not answer.
        """
        self._thread.start()
        atexit.register(self.close)  # an exit that skips close() still halts the arm
        future = self.submit(self._connect)
        try:
            future.result(timeout)
        except URError:
            self.close()
            raise
        except Exception as exc:
            self.close()
            raise URConnectionLost(
                f"cannot connect to the UR controller at {self.host}: {ur_words(exc)}"
            ) from exc

    def close(self) -> None:
        """Halt the arm, end the control script, disconnect and stop the I/O thread.

        The halt runs on the I/O thread after the work already queued (a move sent just
        before is stopped too) and before anything is disconnected. Idempotent; also run at
        interpreter exit.
        """
        if self._closing.is_set():
            return
        self._closing.set()
        atexit.unregister(self.close)
        if self._thread.is_alive():
            self._tasks.put(self.halt)
            self._tasks.put(None)
            self._thread.join(timeout=10.0)

    # ---------------------------------------------------------------- work for the I/O thread

    def submit(self, fn: Callable[[], T]) -> Future[T]:
        """Run ``fn()`` on the I/O thread; its result or exception lands in the Future."""
        future: Future[T] = Future()
        if self._closing.is_set():
            future.set_exception(URConnectionLost("the UR connection is closed"))
            return future

        def run() -> None:
            if not future.set_running_or_notify_cancel():
                return
            if self._halted:
                future.set_exception(URConnectionLost("the UR connection is closed"))
                return
            try:
                future.set_result(fn())
            except BaseException as exc:
                future.set_exception(exc)

        self._tasks.put(run)
        return future

    def watch(self, monitor: Monitor) -> None:
        """Poll ``monitor(self)`` on the I/O thread every cycle until it returns True."""
        self.submit(lambda: self._monitors.append(monitor))

    def add_monitor(self, monitor: Monitor) -> None:
        """(I/O thread only) Poll ``monitor(self)`` every cycle until it returns True."""
        self._monitors.append(monitor)

    def fault(self) -> str:
        """Why the robot cannot move now ("" when it can): :func:`fault_reason` of the last
        state, or a lost connection when that state, with no fault in it, is older than
        ``SILENCE_S`` (the I/O thread has not heard from the controller since). Any thread.
        """
        state = self.state
        reason = fault_reason(state)
        silent = time.monotonic() - state.stamp
        if reason or silent <= SILENCE_S:
            return reason
        return f"{CONNECTION_LOST} (no word from the controller for {silent:.0f} s)"

    def settled_fault(self) -> str:
        """:meth:`fault`, with a control script's end that may yet turn out to be a safety
        stop's ("" until SCRIPT_END_GRACE s after it; the stop's name then, if one came).
        Any thread.
        """
        reason = self.fault()
        if reason == NO_SCRIPT and time.monotonic() - self.script_ended_at < SCRIPT_END_GRACE:
            return ""
        return reason

    def call(self, fn: Callable[[], T], timeout: float = 10.0) -> T:
        """Run ``fn()`` on the I/O thread and wait for it (never from the engine thread)."""
        return self.submit(fn).result(timeout)

    # ---------------------------------------------------------------- the I/O thread

    def _run(self) -> None:
        next_poll = time.monotonic()
        while True:
            timeout = max(0.0, next_poll - time.monotonic())
            try:
                task = self._tasks.get(timeout=timeout)
            except queue.Empty:
                task = _POLL
            if task is None:  # close() queues it after the halt: nothing runs in between
                break
            if task is not _POLL:
                task()
                self.kick()
                continue
            next_poll = time.monotonic() + self._period
            self.refresh()
            self.kick()
            for monitor in list(self._monitors):
                try:
                    finished = monitor(self)
                except Exception:
                    _log.exception("a UR monitor failed")
                    finished = True
                if finished:
                    self._monitors.remove(monitor)
        self._disconnect()

    def kick(self, force: bool = False) -> None:
        """(I/O thread) Kick the control script's watchdog (at most every ``_KICK_PERIOD``
        s unless ``force``); a long wait on the I/O thread calls it to keep the arm going.
        """
        control, receive, now = self.control, self.receive, time.monotonic()
        if (
            not self._watchdog
            or not self._ours  # a program that runs now may be another client's
            or control is None
            or (not force and now - self._last_kick < _KICK_PERIOD)
        ):
            return
        # The last refresh can be a few ms old. A link that dropped since has ur_rtde's
        # control interface reconnecting on its own thread, where it replaces the state our
        # call would read: that crashes the process. Our receive interface never reconnects
        # by itself, so its link, asked just now, says whether the link is still the one
        # the watchdog was set on.
        if receive is None or not receive.isConnected():
            self._watchdog = False
            return
        # A stall is time this thread could not run since its last kick ended, not time
        # spent inside a kick: ur_rtde waits in one for a script that just died (then the
        # script's end is not the watchdog's doing).
        if now - self._kicked > 1.0 / WATCHDOG_HZ:
            self.stalled_at = now
            _log.info("the UR I/O thread stalled for %.2f s", now - self._kicked)
        self._last_kick = now
        try:
            # A script that is not running would make ur_rtde print and wait: kick only one
            # that runs (ending it ends its watchdog too).
            if control.isConnected() and control.isProgramRunning():
                control.kickWatchdog()
        except Exception:  # a dead controller: the recovery monitor says so
            _log.debug("kicking the watchdog failed", exc_info=True)
        finally:
            self._kicked = time.monotonic()

    def halt(self) -> None:
        """(I/O thread) Stop the arm with a controlled deceleration, wait (bounded) until it
        stands, then end the control script. Later work queued on the thread is refused.
        Never raises: a controller that is gone stops the arm by itself (the watchdog).
        """
        self._halted = True
        self._monitors.clear()
        control = self.control
        if control is None or self.taken_over:  # the program that runs is not ours to end
            return
        try:
            if not (control.isConnected() and control.isProgramRunning()):
                return
            control.stopJ(HALT_DECEL, True)  # asynchronous: the watchdog is kicked meanwhile
            deadline = time.monotonic() + _HALT_TIMEOUT
            while time.monotonic() < deadline:
                time.sleep(self._period)
                self.refresh()
                self.kick(force=True)
                if not self.state.moving:
                    break
            self._watchdog = False
            control.stopScript()
        except Exception:
            _log.warning(
                "halting the arm failed: the controller's watchdog stops it", exc_info=True
            )

    def _connect(self) -> None:
        import dashboard_client
        import rtde_receive

        self.dashboard = dashboard_client.DashboardClient(self.host)
        self.dashboard.connect()
        self.version = parse_version(self.dashboard.polyscopeVersion())
        self.receive = rtde_receive.RTDEReceiveInterface(self.host)
        self.refresh()
        if self.state.status_bits & 2:  # robot_status_bits: a program runs already
            _log.warning(
                "UR: a program already runs on the controller at %s (another Instructor or "
                "ur_rtde client?): this session's control script ends it and takes the robot",
                self.host,
            )
        if not fault_reason(URState(**{**self.state.__dict__, "program_running": True})):
            self.start_control()

    def start_control(self, reupload: bool = False) -> None:
        """(I/O thread) Connect the control interface, or upload its script again: when it
        does not run, or with ``reupload`` (a stop ended it, though the controller may not
        have said so yet). After another client took the robot (:data:`TAKEN_OVER`) it is
        the operator's clear: the other program is stopped through the dashboard first.
        """
        self._uploading = True
        try:
            if self.taken_over:
                self._stop_other_program()
            self._start_control(reupload or self.taken_over)
        finally:
            self._uploading = False
        self._ours = self.state.program_running
        if self._ours:
            self.taken_over = False
        self.arm_watchdog()

    def _stop_other_program(self) -> None:
        """(I/O thread) End another client's program through the dashboard (as ur_rtde's
        start-up does with a program it finds running): the operator took the robot back.
        """
        if not self.control.isProgramRunning():
            return
        _log.warning("UR: the operator takes the robot back: the other program is stopped")
        self.dashboard.stop()
        deadline = time.monotonic() + 2.0
        while self.control.isProgramRunning() and time.monotonic() < deadline:
            time.sleep(0.01)

    def _start_control(self, reupload: bool) -> None:
        import rtde_control

        if self.control is None:
            self.control = _control_interface(rtde_control, self.host)
            self.script_runs += 1
        elif reupload or not self.control.isProgramRunning():
            if not self.control.isConnected():
                self.control.reconnect()
            self.script_runs += 1
            self.control.reuploadScript()
            deadline = time.monotonic() + 5.0
            while not self.control.isProgramRunning() and time.monotonic() < deadline:
                time.sleep(0.01)
                self.refresh()
        if any(self._tcp):
            self.control.setTcp(self._tcp)
        if self._payload is not None and self._payload[0] > 0:
            self.control.setPayload(self._payload[0], list(self._payload[1]))
        deadline = time.monotonic() + 2.0
        self.refresh()
        while not self.state.program_running and time.monotonic() < deadline:
            time.sleep(0.005)
            self.refresh()

    @property
    def watchdog_armed(self) -> bool:
        """The control script's watchdog is set and this thread kicks it."""
        return self._watchdog

    def arm_watchdog(self) -> None:
        """(I/O thread) Set the running script's watchdog and start kicking it. Every run of
        the script needs its own (a program stop removes it), and so does a script that ran
        on through a lost connection (kicks stop while the connection is away).
        """
        control = self.control
        self._watchdog = (
            control is not None
            and bool(control.isProgramRunning())
            and bool(control.setWatchdog(WATCHDOG_HZ))
        )
        self._last_kick = self._kicked = time.monotonic()

    def reconnect(self) -> None:
        """(I/O thread) Drop the interfaces and connect afresh (the socket is really gone).

        Raises:
            Exception: whatever ur_rtde raises while the controller is still away.
        """
        self._disconnect()
        self._connect()

    def with_io(self, fn: Callable[[Any], T]) -> T:
        """(I/O thread) ``fn(RTDEIOInterface)`` on an I/O interface opened for this call.

        ur_rtde's RTDEIOInterface never starts synchronisation, so once its controller is gone
        its disconnect (and its destructor) throw and abort the process; a short-lived one is
        closed while the controller still answers.
        """
        import rtde_io

        io = rtde_io.RTDEIOInterface(self.host)
        try:
            return fn(io)
        finally:
            io.disconnect()

    def clear_protective_stop(self) -> None:
        """(I/O thread) What the operator does after a protective stop: close the popup,
        unlock it through the dashboard, and upload the control script again.

        Raises:
            URError: the controller refused to unlock (too early, or another fault).
        """
        self.dashboard.closeSafetyPopup()
        try:
            self.dashboard.unlockProtectiveStop()
        except Exception as exc:
            raise URError(f"unlocking the protective stop failed: {ur_words(exc)}") from exc
        # A protective stop ends the control script; the frame that says so may still be on
        # its way (a loaded machine), and a script thought running was never uploaded again.
        self.start_control(reupload=True)

    def refresh(self) -> None:
        """(I/O thread only) Read the controller's state into :attr:`state` now."""
        try:
            self.state = self._read_state()
        except Exception as exc:
            self.state = URState(connected=False, problem=ur_words(exc))
        if self.state.connected:
            self._note_owner()
            self.last_heard = self.state
        else:
            # No more kicks until this connection is made afresh (start_control arms the
            # watchdog again): a command sent while ur_rtde reconnects by itself makes it
            # reconnect a second time, on this thread, and the two crash the process later.
            # The controller's watchdog stops the script meanwhile, as a lost link should.
            self._watchdog = False

    def _note_owner(self) -> None:
        """(I/O thread) A program seen running after this session's script ended, and not
        started by it, is another client's (a UR runs one program): say so, stop kicking
        (the watchdog's register is the other program's now), and upload again only on the
        operator's clear.
        """
        state = self.state
        if self._uploading or self.control is None:
            return
        if not state.program_running:
            if self._ours:
                self.script_ended_at = time.monotonic()
            self._ours = False
        elif not self._ours and not self.taken_over:
            self.taken_over = True
            self._watchdog = False
            _log.warning("UR: %s", TAKEN_OVER)
        if self.taken_over:
            self.state = URState(**{**state.__dict__, "taken_over": True})

    def _read_state(self) -> URState:
        receive, control = self.receive, self.control
        if receive is None:
            return URState(connected=False, problem="not connected")
        connected = bool(receive.isConnected()) and (control is None or control.isConnected())
        if not connected:
            return URState(connected=False, problem="the controller closed the connection")
        running = False
        async_running, op_id = False, -1
        if control is not None:
            running = bool(control.isProgramRunning())
            status = control.getAsyncOperationProgressEx()
            async_running, op_id = bool(status.isAsyncOperationRunning()), status.operationId()
        return URState(
            connected=True,
            robot_mode=int(receive.getRobotMode()),
            safety_mode=int(receive.getSafetyMode()),
            program_running=running,
            q=tuple(receive.getActualQ()),
            qd=tuple(receive.getActualQd()),
            tcp=tuple(receive.getActualTCPPose()),
            digital_outputs=int(receive.getActualDigitalOutputBits()),
            digital_inputs=int(receive.getActualDigitalInputBits()),
            status_bits=int(receive.getRobotStatus()),
            async_running=async_running,
            async_op_id=op_id,
            stamp=time.monotonic(),
        )

    def _disconnect(self) -> None:
        """Disconnect the three clients side by side: ur_rtde's control and receive
        interfaces each wait about half a second for their threads on disconnect.
        """
        self._watchdog = False
        closing = []
        for name in ("control", "receive", "dashboard"):
            obj = getattr(self, name)
            setattr(self, name, None)
            if obj is not None:
                closing.append(
                    threading.Thread(
                        target=_disconnect_one, args=(name, obj), name=f"ur-close-{name}"
                    )
                )
        for thread in closing:
            thread.start()
        for thread in closing:
            thread.join(timeout=10.0)


def _disconnect_one(name: str, client: Any) -> None:
    try:
        client.disconnect()
    except Exception:  # a dead controller: nothing more to close
        _log.debug("disconnecting %s failed", name, exc_info=True)


def _control_interface(module: Any, host: str, attempts: int = 3) -> Any:
    """ur_rtde's RTDEControlInterface, tried again when its start-up races a script ending.

    At start-up it stops a control script left running by an earlier client through the
    dashboard; when that script ends on its own in between, "stop" fails ("Failed to
    execute: stop") and the constructor throws, though a second try finds nothing to stop.
    """
    for attempt in range(attempts):
        try:
            return module.RTDEControlInterface(host)
        except RuntimeError as exc:
            if "stop" not in str(exc) or attempt == attempts - 1:
                raise
            _log.info("RTDEControlInterface start-up raced a script ending: %s", exc)
            time.sleep(0.2)
    raise AssertionError("unreachable")


_POLL: Callable[[], None] = lambda: None  # noqa: E731  (marks a poll turn of the loop)
