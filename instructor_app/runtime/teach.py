"""RobotTeacher: what the Move panel, the waypoint list and the inspector do with the robot.

It reads the arm's state for display (the backends read a snapshot their own thread keeps,
so that never waits) and sends every command that can wait (a move, a stop, freedrive on
or off, a target's inverse kinematics) to ONE worker thread, in order, as the capabilities
send work off the engine thread. Held actions (a jog arrow, Move here, Freedrive on a real
arm) start on press and end on release: :meth:`release` only sets an event the worker
watches, so the GUI thread never waits for the arm (but for :meth:`leave_freedrive`, as a
run starts, which turns the simulated cell's toggled freedrive off before the plan moves).

It works on any cell whose interfaces follow the backend Protocols: ``arm``
(:class:`capabilities.motion.backend.ArmBackend`), ``freedrive``
(:class:`capabilities.freedrive.backend.FreedriveBackend`) and ``world``
(:class:`capabilities.motion.backend.WorldBackend`).
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Signal

from capabilities.motion.jog import JogFailed, Jogger, JogSpeeds
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import TargetResolver
from engine.operations import OperationFailed
from engine.types import Pose
from instructor_app.idle_timer import IdlePollTimer

__all__ = ["ArmState", "RobotTeacher", "MOVE_HERE_FRACTION"]

MOVE_HERE_FRACTION = 0.25  # Move here runs at a quarter of the slider's speed, as PolyScope
_POLL_MS = 100
# After _IDLE_READS reads in a row that found the arm where it was, it is read only every
# _IDLE_POLL_MS (a read that finds it moved makes it quick again).
_IDLE_READS = 20
_IDLE_POLL_MS = 300
# A joint that moved less than this (rad), a TCP less than this (m, quaternion components),
# did not move: the resting simulated arm's numerical jitter is not a change to show.
_STILL = 1e-6
_DRAG_SETTLE_S = 5.0  # at most this long for the arm to reach a released drag


@dataclass(frozen=True)
class ArmState:
    """What the panels show: the measured joints (rad), the TCP pose, freedrive on or off."""

    joints: tuple[float, ...]
    tcp: Pose
    freedrive: bool = False


def _same_state(a: ArmState | None, b: ArmState | None) -> bool:
    """The same state to show: joints and TCP within ``_STILL``, freedrive the same."""
    if a is None or b is None:
        return a is b
    numbers_a = (*a.joints, *a.tcp.position, *a.tcp.orientation)
    numbers_b = (*b.joints, *b.tcp.position, *b.tcp.orientation)
    return (
        a.freedrive == b.freedrive
        and len(numbers_a) == len(numbers_b)
        and all(abs(x - y) <= _STILL for x, y in zip(numbers_a, numbers_b, strict=True))
    )


class RobotTeacher(QObject):
    """Jog, freedrive, move-here and drag for the cell in use, off the GUI thread.

    Args:
        registry: the cell's registry (its ``cell.interfaces()`` are used).
        poll_ms: how often the arm's state is read for display.

    Signals:
        state_changed(object): a new :class:`ArmState` (None: no arm or no state).
        availability_changed(): the cell changed, or a run started or ended.
        finished(str, str): a command ended: (what, problem; "" when it went well).
        message(str): words for the status bar.
        preview_ready(object): the joints (rad) a previewed target puts the arm at, or None.
        freedrive_left(): a toggled freedrive is over: :meth:`leave_freedrive` turned it off
            (a run is starting), or the cell changed.
    """

    state_changed = Signal(object)
    availability_changed = Signal()
    finished = Signal(str, str)
    message = Signal(str)
    preview_ready = Signal(object)
    freedrive_left = Signal()

    def __init__(self, registry: Any = None, poll_ms: int = _POLL_MS, parent: Any = None) -> None:
        super().__init__(parent)
        self._interfaces: dict[str, Any] = {}
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="costar-teach")
        self._released = threading.Event()
        self._released.set()
        self._step_cancel = threading.Event()
        self._drag_lock = threading.Lock()
        self._drag_pose: Pose | None = None
        self._drag_pending = False
        self._drag_started_freedrive = False
        self._drag_handle: Any = None
        self._run_active = False
        self._symmetries = SymmetryTable()
        self.speed_fraction = 0.25
        self.state: ArmState | None = None
        self._timer = IdlePollTimer(poll_ms, _IDLE_POLL_MS, _IDLE_READS, self)
        self._timer.timeout.connect(self.poll)
        self._timer.start()
        self.set_registry(registry)

    # ------------------------------------------------------------------ cell

    def set_registry(self, registry: Any) -> None:
        """Use another cell (what runs on the old one is stopped, and a toggled Freedrive is
        over: a new cell starts with it off, the same cell's is turned off).
        """
        self.stop_all()
        old_drive = self._interfaces.get("freedrive")
        cell = getattr(registry, "cell", None)
        self._interfaces = dict(cell.interfaces()) if cell is not None else {}
        drive = self._interfaces.get("freedrive")
        if drive is old_drive and drive is not None:
            with contextlib.suppress(Exception):  # a snapshot read: never waits
                if drive.freedrive_active():
                    self.release_freedrive()
        self.freedrive_left.emit()
        self.poll()
        self.availability_changed.emit()

    def set_run_active(self, running: bool) -> None:
        """While a plan runs, the robot is the plan's: teaching commands are refused."""
        if running:
            self.stop_all()
        self._run_active = running
        self.availability_changed.emit()

    def interface(self, name: str) -> Any:
        """The cell's interface ``name`` (None when it has none)."""
        return self._interfaces.get(name)

    def unavailable_reason(self, need: str = "arm") -> str:
        """Why the robot cannot be taught now ("" when it can)."""
        if need not in self._interfaces:
            return f"this cell has no {need}"
        if self._run_active:
            return "a plan is running"
        return ""

    # ------------------------------------------------------------------ state

    def poll(self) -> None:
        """Read the arm's state (a snapshot: never waits) and tell the panels if it changed."""
        state = self.read_state()
        changed = not _same_state(state, self.state)
        self._timer.polled(changed)
        if not changed:
            return
        self.state = state
        self.state_changed.emit(state)

    def read_state(self) -> ArmState | None:
        arm = self._interfaces.get("arm")
        if arm is None:
            return None
        try:
            drive = self._interfaces.get("freedrive")
            on = bool(drive.freedrive_active()) if drive is not None else False
            return ArmState(tuple(arm.joint_positions()), arm.tcp_pose(), on)
        except Exception:  # a real arm that is not running has no pose to show
            return None

    def resolver(self) -> TargetResolver:
        """Resolves waypoints against the cell's world model (detections, never truth)."""
        return TargetResolver(self._interfaces.get("world"), self._symmetries)

    # ------------------------------------------------------------------ commands

    def jog_step(self, frame: str, axis: str, amount: float) -> bool:
        """One step of the tool (m or rad) in the base or tool frame."""
        jogger = self._jogger()
        fraction = self.speed_fraction
        return jogger is not None and self._step(
            f"jog {frame} {axis}",
            lambda ev: jogger.follow(jogger.step(frame, axis, amount, fraction), ev),
        )

    def jog_joint_step(self, joint: int, amount: float) -> bool:
        """One step of one joint (rad)."""
        jogger = self._jogger()
        fraction = self.speed_fraction
        return jogger is not None and self._step(
            f"jog joint {joint + 1}",
            lambda ev: jogger.follow(jogger.step_joint(joint, amount, fraction), ev),
        )

    def hold_jog(self, frame: str, axis: str, sign: int) -> bool:
        """Jog the tool while held (until :meth:`release`)."""
        jogger = self._jogger()
        fraction = self.speed_fraction
        return jogger is not None and self._hold(
            f"jog {frame} {axis}", lambda ev: jogger.hold(frame, axis, sign, fraction, ev)
        )

    def hold_joint(self, joint: int, sign: int) -> bool:
        """Turn one joint while held."""
        jogger = self._jogger()
        fraction = self.speed_fraction
        return jogger is not None and self._hold(
            f"jog joint {joint + 1}", lambda ev: jogger.hold_joint(joint, sign, fraction, ev)
        )

    def hold_move_to(self, target: Any, reference: Any = "", what: str = "move here") -> bool:
        """Move to a Pose or Waypoint while held, at reduced speed (released: the arm stops).

        A relative waypoint is composed with where the cell last detected its object.
        """
        jogger = self._jogger()
        fraction = self.speed_fraction * MOVE_HERE_FRACTION
        resolver = self.resolver()

        def move(released: threading.Event) -> str:
            assert jogger is not None
            current = self._interfaces["arm"].tcp_pose()
            try:
                resolved = resolver.resolve(target, reference, current)
            except OperationFailed as exc:
                raise JogFailed(str(exc)) from exc
            return jogger.go_to(resolved, fraction, released)

        return jogger is not None and self._hold(what, move)

    def press_freedrive(self) -> bool:
        """Hand guiding on (until :meth:`release_freedrive`)."""
        drive = self._ready("freedrive")
        if drive is None:
            return False
        self.stop_all()
        return self._submit("freedrive", lambda: drive.set_freedrive(True) or "")

    def release_freedrive(self) -> bool:
        """Hand guiding off: the arm holds where the hand left it."""
        drive = self._interfaces.get("freedrive")
        return drive is not None and self._submit(
            "freedrive off", lambda: drive.set_freedrive(False) or ""
        )

    def leave_freedrive(self) -> None:
        """Freedrive off now, on the calling thread: a plan is about to command the arm (a
        move is refused in freedrive). The one wait outside the worker, and short: freedrive
        is left on only by the simulated cell's toggle (a real arm's button is held).
        """
        drive = self._interfaces.get("freedrive")
        if drive is None:
            return
        try:
            if drive.freedrive_active():
                drive.set_freedrive(False)
        except Exception as exc:  # a backend error is told, never raised into the GUI
            self.message.emit(f"Freedrive off: {type(exc).__name__}: {exc}")
        self.freedrive_left.emit()

    def release(self) -> None:
        """End the held action (the worker stops the arm); never waits."""
        self._released.set()

    def stop_all(self) -> None:
        """End the held action and a step under way."""
        self._released.set()
        self._step_cancel.set()

    def drag_to(self, pose: Pose) -> bool:
        """The tool follows a dragged pose (the newest one wins): in freedrive where the cell
        can pull its arm by the tool (the simulated cell), else by joint moves through IK.
        """
        arm = self._ready("arm")
        if arm is None:
            return False
        with self._drag_lock:
            self._drag_pose = pose
            if self._drag_pending:
                return True
            self._drag_pending = True
        return self._submit("drag", self._drag_newest)

    def end_drag(self) -> bool:
        """The drag is over: freedrive that the drag turned on is turned off again."""
        drive = self._interfaces.get("freedrive")
        if drive is None:
            return False

        def end() -> str:
            handle, self._drag_handle = self._drag_handle, None
            if handle is not None:  # let the arm reach where the hand let go
                arrived = threading.Event()
                handle.add_done_callback(lambda _h: arrived.set())
                arrived.wait(_DRAG_SETTLE_S)
            if self._drag_started_freedrive:
                self._drag_started_freedrive = False
                drive.set_freedrive(False)
            return ""

        return self._submit("drag end", end)

    def preview(self, target: Any, reference: Any = "") -> bool:
        """Work out (on the worker) the joints at a Pose or Waypoint: ``preview_ready``."""
        arm = self._interfaces.get("arm")
        if arm is None or target is None:
            self.preview_ready.emit(None)
            return False
        resolver = self.resolver()

        def work() -> str:
            joints: tuple[float, ...] | None = None
            try:
                resolved = resolver.resolve(target, reference, arm.tcp_pose())
            except OperationFailed as exc:
                self.preview_ready.emit(None)
                return f"cannot preview: {exc}"
            if resolved.joints is not None:
                joints = tuple(resolved.joints.positions)
            for pose in resolved.poses:
                joints = arm.inverse_kinematics(pose)
                if joints is not None:
                    break
            self.preview_ready.emit(joints)
            return (
                "" if joints is not None else f"cannot preview: {resolved.describe} is unreachable"
            )

        return self._submit("preview", work)

    def shutdown(self) -> None:
        """Release, and let the worker finish (a stop already sent still reaches the arm)."""
        self._timer.stop()
        self.stop_all()
        self._pool.shutdown(wait=False, cancel_futures=True)

    # ------------------------------------------------------------------ internals

    def _ready(self, need: str) -> Any:
        reason = self.unavailable_reason(need)
        if reason:
            self.message.emit(f"Cannot move the robot: {reason}.")
            return None
        return self._interfaces[need]

    def _jogger(self) -> Jogger | None:
        arm = self._ready("arm")
        return Jogger(arm) if arm is not None else None

    def _hold(self, what: str, work: Callable[[threading.Event], str]) -> bool:
        self.stop_all()  # a new press ends what ran before
        released = threading.Event()
        self._released = released
        return self._submit(what, lambda: work(released))

    def _step(self, what: str, work: Callable[[threading.Event], str]) -> bool:
        """A click's command: the button's release does not stop it, a new command does."""
        self.stop_all()
        cancel = threading.Event()
        self._step_cancel = cancel
        return self._submit(what, lambda: work(cancel))

    def _submit(self, what: str, work: Callable[[], str]) -> bool:
        def run() -> None:
            try:
                problem = work()
            except JogFailed as exc:
                problem = str(exc)
            except Exception as exc:  # a backend error ends the command, never the GUI
                problem = f"{type(exc).__name__}: {exc}"
            with contextlib.suppress(RuntimeError):  # the window is gone: nobody to tell
                self.finished.emit(what, problem or "")
                if problem:
                    self.message.emit(f"{what.capitalize()}: {problem}")

        try:
            self._pool.submit(run)
        except RuntimeError:  # shut down
            return False
        return True

    def _drag_newest(self) -> str:
        with self._drag_lock:
            pose, self._drag_pose, self._drag_pending = self._drag_pose, None, False
        if pose is None:
            return ""
        drive = self._interfaces.get("freedrive")
        if drive is not None and hasattr(drive, "freedrive_drag_to"):
            if not drive.freedrive_active():
                drive.set_freedrive(True)
                self._drag_started_freedrive = True
            # a newer drag replaces this one on the physics thread
            self._drag_handle = drive.freedrive_drag_to(pose)
            return ""
        arm = self._interfaces["arm"]
        q = arm.inverse_kinematics(pose)
        if q is None:
            return "the arm cannot reach that pose"
        speeds = JogSpeeds()
        arm.move_joints(q, speeds.joint, speeds.joint_accel)  # a newer target preempts it
        return ""
