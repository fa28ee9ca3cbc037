"""Runs a tree in its own thread at a rate, and tells listeners what happens.

The engine thread ticks; when an asynchronous job finishes it wakes the engine, which ticks
again at once instead of waiting for the next period. Events are queued by the engine
thread and delivered to listeners by a separate dispatcher thread, so a slow listener
(a GUI, a file) never holds up a tick.

A cell that can stop on its own (a real robot's protective stop, a lost connection) gives the
executor a ``hold`` check (``engine.hold``), asked before every tick. When a stop begins and
every running leaf sits in the body of a Catch that takes the stop's error type, the stop is
thrown into the plan: those leaves fail with it and the handlers run (Intera), and the same
stop does not hold the run while it lasts (the handler is clearing it). Otherwise the run is
held (the running leaves are halted, nothing is ticked, a RunHeld event says why); once the
cell is clear again the run goes on, and the composites tick the halted leaves afresh
(PolyScope). A stop of no known type (``failed``: power off, a stopped script) is always held.

In lockstep (a :class:`Lockstep`: a simulated cell, run as fast as it can or paced to real
time) the world goes on only with the engine's clock: after each tick the executor lets it
run one period and waits until it has, and the next tick comes then, not earlier (a job that
finishes does not bring it forward). The same plan, scene and seed then give the same ticks,
however busy the machine is. While the run is paused the world runs free.

A :class:`~engine.debugger.Debugger` says where the run pauses by itself (breakpoints,
steps, a run to a node): the engine thread then waits inside the tick, exactly there, as a
paused run waits between ticks (the world runs free, nothing is ticked), and a RunPaused
event says where and why.
"""

from __future__ import annotations

import collections
import enum
import threading
import time
from typing import Any, Protocol

from engine.blackboard import OPERATOR
from engine.debugger import Debugger, Step
from engine.dispatcher import Dispatcher
from engine.error_types import ErrorType
from engine.events import (
    BlackboardWritten,
    Event,
    Listener,
    LogMessage,
    RunFinished,
    RunHeld,
    RunPaused,
    RunStarted,
    StatusChanged,
)
from engine.hold import Hold, HoldCheck, catchers, stopped_leaves, throw
from engine.node import Node
from engine.status import FAILURE, RUNNING, Status
from engine.tree import BehaviorTree

__all__ = ["Executor", "ExecutorState", "Lockstep", "run_to_end"]


class Lockstep(Protocol):
    """A world that goes on only with the engine's clock (a simulated cell, run as fast as
    it can).
    """

    def advance(self, seconds: float) -> None:
        """Let the world go ``seconds`` further; return once it has."""
        ...

    def release(self) -> None:
        """The run is over: the world goes on by itself again."""
        ...


class _Stopped(Exception):
    """Raised on the engine thread, out of a tick paused inside, when the run is stopped."""


class ExecutorState(str, enum.Enum):
    """Where the executor is: ready to start, running, paused or finished."""

    READY = "ready"
    RUNNING = "running"
    PAUSED = "paused"
    FINISHED = "finished"


class Executor:
    """Ticks a tree in a thread: start, pause, resume, step, stop.

    Args:
        tree: the tree to run.
        rate_hz: ticks per second when nothing wakes it earlier (the paper's delta).
        listeners: callables that receive every :mod:`engine.events` event.
        plan_name: for the RunStarted event.
        hold: asked before every tick; a Hold (why, and its error type) stops the run: it is
            thrown into the plan's Catch nodes that take it, else the run is held.
        lockstep: the world to advance one period after each tick (see the module doc);
            None: ticks come by the wall clock.
        inline: listeners called on the engine thread as each event happens, before the
            other listeners hear it: for what must act at the tick itself (a simulated
            cell's actors, in lockstep), quickly and without waiting on the engine.
        debugger: breakpoints, skipped nodes, forced results (default: a debugger with
            none, which costs the run nothing).
    """

    def __init__(
        self,
        tree: BehaviorTree,
        rate_hz: float = 20.0,
        listeners: list[Listener] | None = None,
        plan_name: str = "",
        hold: HoldCheck | None = None,
        lockstep: Lockstep | None = None,
        inline: list[Listener] | None = None,
        debugger: Debugger | None = None,
    ) -> None:
        if rate_hz <= 0:
            raise ValueError(f"rate must be above 0 Hz, not {rate_hz}")
        self.tree = tree
        self.period = 1.0 / rate_hz
        self.plan_name = plan_name
        self._listeners: list[Listener] = list(listeners or [])
        self._cond = threading.Condition()
        self._woken = False
        self._paused = False
        self._steps = 0
        self._stop_reason: str | None = None
        self._edits: collections.deque[tuple[str, Any, str]] = collections.deque()
        self._state = ExecutorState.READY
        self._hold = hold
        self._lockstep = lockstep
        self._held = ""  # the reason the run is held now ("" when it is not)
        self._thrown: Hold | None = None  # a stop thrown into the plan, while it lasts
        self._failures: list[str] = []  # leaf failure messages since the cell was last clear
        self._result: RunFinished | None = None
        self._done = threading.Event()
        self._inline: list[Listener] = list(inline or [])
        self.debugger = debugger if debugger is not None else Debugger()
        self._dispatcher = Dispatcher(self._listeners)
        self._thread = threading.Thread(target=self._run, name="costar-engine", daemon=True)

    # ------------------------------------------------------------------ control (any thread)

    def add_listener(self, listener: Listener) -> None:
        """Add before start()."""
        self._listeners.append(listener)

    @property
    def state(self) -> ExecutorState:
        return self._state

    @property
    def result(self) -> RunFinished | None:
        """The RunFinished event once the run ended."""
        return self._result

    def start(self, paused: bool = False) -> None:
        """Start the engine thread (paused: wait for step() or resume())."""
        if self._state is not ExecutorState.READY:
            raise RuntimeError("an executor runs once; build a new one to run again")
        self._paused = paused
        self._state = ExecutorState.PAUSED if paused else ExecutorState.RUNNING
        self._attach()
        self._dispatcher.start()
        self._thread.start()

    def pause(self) -> None:
        """Pause after the current tick (a step over from here is a step to the next event)."""
        with self._cond:
            if self._state is ExecutorState.RUNNING:
                self.debugger.current = ""
                self._paused = True
                self._state = ExecutorState.PAUSED

    def resume(self) -> None:
        """Go on (continue): a step or a run to a node armed before is forgotten."""
        with self._cond:
            if self._state is ExecutorState.PAUSED:
                self.debugger.arm(None)
                self._paused = False
                self._steps = 0  # steps not taken yet are void once running again
                self._state = ExecutorState.RUNNING
                self._cond.notify()

    def step(self) -> None:
        """One tick while paused; ignored otherwise (a step asked for while running must not
        turn into a surprise tick after a later pause).
        """
        with self._cond:
            if self._state is not ExecutorState.PAUSED:
                return
            self._steps += 1
            self._cond.notify()

    def set_entry(self, key: str, value: Any, writer: str = OPERATOR) -> None:
        """Set a blackboard entry while the run is paused (any thread).

        The value is checked here against the entry's declared type (BlackboardError,
        naming the entry and the type); the engine thread writes it between ticks, and the
        write is reported as a BlackboardWritten event like any other. Raises RuntimeError
        when the run is not paused.
        """
        self.tree.blackboard.check(key, value)
        with self._cond:
            if self._state is not ExecutorState.PAUSED:
                raise RuntimeError(f"{key} can be set only while the run is paused")
            self._edits.append((key, value, writer))
            self._cond.notify()

    def step_next(self) -> None:
        """While paused: run to the next status change of any node, and pause there."""
        self._go(Step.NEXT)

    def step_over(self) -> None:
        """While paused: run the node paused at to its end, and pause there (see
        :mod:`engine.debugger`).
        """
        self._go(Step.OVER)

    def run_to(self, node_id: str) -> None:
        """While paused: run on until ``node_id`` is about to start, and pause there."""
        self._go(None, node_id)

    def _go(self, step: Step | None, run_to: str = "") -> None:
        with self._cond:
            if self._state is not ExecutorState.PAUSED:
                return
            self.debugger.arm(step, run_to)
            self._paused = False
            self._steps = 0
            self._state = ExecutorState.RUNNING
            self._cond.notify()

    def stop(self, reason: str = "stopped", timeout: float | None = 5.0) -> None:
        """Halt what runs and end the run; waits for the engine thread (up to ``timeout``)."""
        with self._cond:
            if self._stop_reason is None:
                self._stop_reason = reason
            self._cond.notify()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(timeout)

    def wake(self) -> None:
        """Tick now rather than at the next period (jobs call this when they finish)."""
        with self._cond:
            self._woken = True
            self._cond.notify()

    def wait(self, timeout: float | None = None) -> RunFinished | None:
        """Block until the run ended and its events were delivered; the result or None."""
        if not self._done.wait(timeout):
            return None
        self._dispatcher.join(timeout)
        return self._result

    # ------------------------------------------------------------------ engine thread

    def _attach(self) -> None:
        ctx = self.tree.ctx
        put = self._emit
        clock = time.monotonic

        debugger = self.debugger

        def on_status(node: Node, old: Status, new: Status) -> None:
            error = node.error.value if new is FAILURE and node.error is not None else ""
            if error and not node.children and self._hold is not None:
                self._failures.append(node.message)
            put(StatusChanged(ctx.tick_count, node.id, old, new, node.message, clock(), error))
            if debugger.step is not None:
                debugger.on_status(node, old, new)

        def on_log(node_id: str, message: str) -> None:
            put(LogMessage(ctx.tick_count, node_id, message, clock()))

        def on_write(key: str, value: object, writer: str) -> None:
            put(BlackboardWritten(ctx.tick_count, key, value, writer, clock()))

        ctx.status_sink = on_status
        ctx.log_sink = on_log
        ctx.wake = self.wake
        self.tree.blackboard.add_write_listener(on_write)
        debugger.attach(self.tree, self._break)

    def _break(self, node: Node, where: str, why: str) -> None:
        """Pause here, inside the tick, until resumed, stepped or stopped (engine thread).

        Raises:
            _Stopped: the run was stopped while paused here.
        """
        with self._cond:
            if self._stop_reason is None:
                self._paused = True
                self._state = ExecutorState.PAUSED
        self._emit(RunPaused(self.tree.ctx.tick_count, node.id, where, why, time.monotonic()))
        if self._lockstep is not None:
            self._release(self._lockstep)  # the world runs free, the robot held
        with self._cond:
            while self._paused and self._stop_reason is None:
                self._apply_edits()  # values set at a breakpoint reach the node it paused
                if self._steps:  # one tick: this one goes on, the run pauses after it
                    self._steps -= 1
                    break
                self._cond.wait()
            self._apply_edits()
            if self._stop_reason is not None:
                raise _Stopped(self._stop_reason)

    def _wait_for_turn(self, deadline: float) -> str | None:
        """Sleep until the next tick is due; returns a stop reason when stopping."""
        with self._cond:
            while True:
                if self._stop_reason is not None:
                    return self._stop_reason
                self._apply_edits()
                if self._paused:
                    if self._steps:
                        self._steps -= 1
                        return None
                    if self._lockstep is not None:
                        # Paused, the world runs free (the robot is held, not frozen in
                        # mid-air); the next tick's advance drives it again.
                        self._release(self._lockstep)
                    self._cond.wait()
                    continue
                if self._woken:
                    self._woken = False
                    return None
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._cond.wait(remaining)

    def _apply_edits(self) -> None:
        """Write the values set while paused (engine thread, between ticks)."""
        while self._edits:
            key, value, writer = self._edits.popleft()
            try:
                self.tree.blackboard.set(key, value, writer)
            except Exception as exc:  # checked when asked; a listener's bug must not end it
                self._emit(LogMessage(0, "root", f"{key} was not set: {exc}", time.monotonic()))

    def _run(self) -> None:
        self._emit(RunStarted(time.monotonic(), self.plan_name))
        status: Status = RUNNING
        reason, message = "finished", ""
        next_tick = time.monotonic()
        try:
            while True:
                stop = self._wait_for_turn(next_tick)
                if stop is not None:
                    reason = stop
                    break
                # In lockstep the next tick is due once the world has gone one period on.
                next_tick = 0.0 if self._lockstep else time.monotonic() + self.period
                if not self._held_now():
                    status = self.tree.tick()
                    if status is not RUNNING:
                        message = self.tree.root.message
                        break
                if self._lockstep is not None:
                    self._lockstep.advance(self.period)
        except _Stopped as stopped:  # stopped while paused inside a tick
            reason = str(stopped)
        except Exception as exc:  # a bug in the engine itself: end the run, keep the app
            reason, message = "error", f"{type(exc).__name__}: {exc}"
        try:
            if status is RUNNING or reason != "finished":
                self._halt_all()
        finally:
            if self._lockstep is not None:
                self._release(self._lockstep)
        self._finish(status, reason, message)

    def _release(self, lockstep: Lockstep) -> None:
        try:
            lockstep.release()
        except Exception as exc:  # a closed cell: nothing to release
            self._emit(LogMessage(0, "root", f"error ending the lockstep: {exc}", time.monotonic()))

    @property
    def held(self) -> str:
        """Why the run is held now ("" when it is not)."""
        return self._held

    def _held_now(self) -> bool:
        """Ask the hold check; throw a stop into the plan, or halt the running leaves when a
        hold begins (engine thread).
        """
        if self._hold is None:
            return False
        try:
            hold = self._hold()
        except Exception as exc:  # a broken check holds the run rather than ignoring the cell
            hold = Hold(f"the cell's safety check failed: {type(exc).__name__}: {exc}")
        reason = hold.reason if hold is not None else ""
        if not reason:
            self._thrown = None
            self._failures.clear()
        elif hold == self._thrown or (not self._held and self._thrown_now(hold)):
            reason = ""  # the plan handles this stop: tick on
        if reason == self._held:
            return bool(reason)
        if reason and not self._held:
            for leaf in self.tree.running_leaves():
                leaf.reset()
        self._held = reason
        self._emit(RunHeld(self.tree.ctx.tick_count, reason, time.monotonic()))
        return bool(reason)

    def _thrown_now(self, hold: Hold | None) -> bool:
        """Throw a stop that began into the plan when its Catch nodes take it."""
        if hold is None or hold.error is ErrorType.FAILED:
            return False
        if any(hold.reason in message for message in self._failures):
            self._thrown = hold  # a node already failed with it: the plan has seen it
            return True
        leaves = stopped_leaves(self.tree.running_leaves(), hold)
        if catchers(leaves, hold.error) is None:
            return False
        throw(leaves, hold)
        for leaf in leaves:
            self._emit(
                LogMessage(
                    self.tree.ctx.tick_count,
                    leaf.id,
                    f"the cell threw {hold.error.value} into the plan: {hold.reason}",
                    time.monotonic(),
                )
            )
        self._thrown = hold
        return True

    def _emit(self, event: Event) -> None:
        """Hand an event to the inline listeners now, then to the dispatcher (engine thread)."""
        for listener in self._inline:
            try:
                listener(event)
            except Exception as exc:  # a broken listener must not end the run
                self._dispatcher.put(
                    LogMessage(0, "root", f"a listener failed: {exc}", time.monotonic())
                )
        self._dispatcher.put(event)

    def _halt_all(self) -> None:
        try:
            self.tree.reset()
        except Exception as exc:
            self._emit(LogMessage(0, "root", f"error while halting: {exc}", time.monotonic()))

    def _finish(self, status: Status, reason: str, message: str) -> None:
        # A stopped run reports the status of its last tick (RUNNING when it was cut short).
        self._result = RunFinished(
            self.tree.ctx.tick_count, status, reason, message, time.monotonic()
        )
        self._state = ExecutorState.FINISHED
        self._emit(self._result)
        self._dispatcher.close()
        self._done.set()


def run_to_end(
    tree: BehaviorTree,
    rate_hz: float = 20.0,
    timeout: float | None = None,
    listeners: list[Listener] | None = None,
    lockstep: Lockstep | None = None,
) -> RunFinished:
    """Run a tree in an executor until it finishes or ``timeout`` seconds pass."""
    executor = Executor(tree, rate_hz, listeners, lockstep=lockstep)
    executor.start()
    result = executor.wait(timeout)
    if result is None:
        executor.stop("timeout")
        result = executor.wait(5.0)
    assert result is not None
    return result
