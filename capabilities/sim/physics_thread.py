"""The one thread that touches pybullet: it drains a command queue and steps the world.

Every other thread talks to pybullet through ``call`` (run a function here and get its
result) or ``post`` (fire and forget). Step hooks registered by the cell's controllers run
before each ``stepSimulation`` (control) and after it (sensing). Simulated time advances by
``time_step`` per step; with a speed factor the loop is paced against the wall clock,
without one it runs as fast as it can, handing the GIL to other threads every
``_YIELD_S`` of stepping, or every step inside :meth:`PhysicsThread.sharing` (another thread
computes in Python: perception). Inside :meth:`PhysicsThread.standing_still` (lockstep:
perception computing on another thread) the world is not stepped and simulated time stands
still, as it already does while a call (a camera render) is served.

In lockstep (:meth:`PhysicsThread.advance`, a run's executor drives it): the world steps only as far as
the engine's clock lets it, one tick's period at a time, and stands still in between while
the engine ticks; :meth:`PhysicsThread.release` lets it run free again. A job that began at a
tick holds the world from that tick (:meth:`PhysicsThread.hold`) and hands its result over at
a set simulated time (:meth:`PhysicsThread.at`), on this thread: what the engine sees at
each tick does not depend on how busy the machine is.

At rest: a loop paced against the wall clock stops stepping once nothing has moved for
``REST_AFTER_S`` of simulated time (every rest check the cell registered says so: all bodies
and joints slower than a crawl, no command under way), no command is in flight, no thread
waits for simulated time and no step hook that may act by itself (an actor's) is registered.
Simulated time then goes on with the wall clock without stepping (what stepping a world in
which nothing moves would give), and the thread sleeps until a call comes. A call made with
:meth:`PhysicsThread.peek` (a read: the live view's snapshots) is served at rest; any other
call or post, a thread waiting for simulated time, or a rest check saying no ends the rest.
"""

from __future__ import annotations

import contextlib
import heapq
import itertools
import logging
import queue
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from contextlib import contextmanager
from typing import Any, TypeVar

from capabilities.bullet import pybullet
from capabilities.robot.commands import CommandHandle
from capabilities.sim.errors import SimError

__all__ = ["PhysicsThread", "StepHook"]

T = TypeVar("T")
StepHook = Callable[[float], None]
_log = logging.getLogger(__name__)
# Wall seconds of stepping between two hand-overs of the GIL when no thread said it computes.
# pybullet steps without releasing the GIL and a hand-over (time.sleep(0)) costs a system
# call (~55 us on a VM), so it is not done every step unless another thread asks for it.
_YIELD_S = 0.001
REST_AFTER_S = 0.5  # simulated seconds without a move before a paced loop rests
_REST_CHECK_STEPS = 12  # the rest checks run every this many steps (20 times a second)
_REST_WAIT_S = 0.1  # at rest, the loop looks at the rest checks and the clock this often


class PhysicsThread:
    """Owns a pybullet DIRECT client and steps it on its own thread.

    Args:
        setup: run on the physics thread right after connecting, with the client id
            (builds the world); an exception there makes ``start`` raise.
        speed: real-time factor (1.0 real time); None runs as fast as possible.
        time_step: seconds per physics step (1/240 by default).
        still: the world stands still once built, as between two :meth:`advance` calls,
            until the first advance or :meth:`release` (a run in lockstep then begins at
            simulated time 0, however long its set-up took).
    """

    def __init__(
        self,
        setup: Callable[[int], None],
        speed: float | None = None,
        time_step: float = 1.0 / 240.0,
        still: bool = False,
    ) -> None:
        if speed is not None and not speed > 0:
            raise SimError(f"speed must be above 0 or None, got {speed}")
        self._setup = setup
        self.speed = speed
        self.time_step = time_step
        self.client = -1
        self.steps = 0
        self._time = 0.0
        self._queue: queue.SimpleQueue[tuple[Callable[[int], Any], Future[Any], bool] | None]
        self._queue = queue.SimpleQueue()
        self._serving_s = 0.0  # wall seconds spent running posted calls (not simulated time)
        self._pre_hooks: list[StepHook] = []
        self._post_hooks: list[StepHook] = []
        # (simulated time, order, what to run then, run it also when the cell closes): the
        # events of threads waiting for simulated time, and results handed over at a time.
        self._timers: list[tuple[float, int, Callable[[], None], bool]] = []
        self._timer_ids = itertools.count()
        self._timer_lock = threading.Lock()
        self._holds = 0  # blocks in standing_still: while above 0 the world is not stepped
        self._hold_lock = threading.Lock()
        self._sharers = 0  # blocks in sharing: while above 0 the GIL is handed over every step
        self._in_flight = 0  # commands posted and not finished (see waited_on)
        self._lockstep = still  # in lockstep with an engine: step only within the budget
        self._budget = 0  # steps the engine's clock still allows (driven)
        self._budget_spent = threading.Event()
        self._gates: list[Callable[[], bool]] = []  # all must say True for a step
        self._rest_checks: list[Callable[[], bool]] = []  # all must say True for a rest
        self._restless: list[StepHook] = []  # hooks that may act by themselves: no rest
        self._quiet_steps = 0  # steps in a row at which every rest check said True
        self.resting = False  # the loop rests: nothing moves, time goes on without steps
        self.rests = 0  # times the loop came to rest
        self._rested_steps = 0  # steps of simulated time that passed at rest
        self._woken = False  # a call other than a peek was served at rest
        self._ready = threading.Event()
        self._stopping = threading.Event()
        self._setup_error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="sim-physics", daemon=True)

    # ------------------------------------------------------------------ lifecycle

    def start(self) -> None:
        """Start the thread and wait until the world is built."""
        self._thread.start()
        self._ready.wait()
        if self._setup_error is not None:
            self._thread.join()
            raise SimError(f"building the simulated cell failed: {self._setup_error}") from (
                self._setup_error
            )

    def stop(self) -> None:
        """Stop stepping, disconnect pybullet and join the thread. Idempotent."""
        if not self._thread.is_alive():
            return
        self._stopping.set()
        self._queue.put(None)
        self._thread.join()

    @property
    def running(self) -> bool:
        """True while the thread steps the world."""
        return self._thread.is_alive() and not self._stopping.is_set()

    def in_thread(self) -> bool:
        """True when called from the physics thread itself."""
        return threading.current_thread() is self._thread

    # ------------------------------------------------------------------ commands

    def time(self) -> float:
        """Simulated seconds since start."""
        return self._time

    def post(self, fn: Callable[[int], T]) -> Future[T]:
        """Queue ``fn(client)`` to run on the physics thread before the next step."""
        return self._post(fn, wakes=True)

    def _post(self, fn: Callable[[int], T], wakes: bool) -> Future[T]:
        future: Future[T] = Future()
        if not self.running:
            future.set_exception(SimError("the simulated cell is not running"))
            return future
        self._queue.put((fn, future, wakes))
        return future

    def call(self, fn: Callable[[int], T], timeout: float | None = 60.0) -> T:
        """Run ``fn(client)`` on the physics thread and return its result (inline if here)."""
        if self.in_thread():
            return fn(self.client)
        return self.post(fn).result(timeout)

    def peek(self, fn: Callable[[int], T], timeout: float | None = 60.0) -> T:
        """As :meth:`call`, for a ``fn`` that only reads the world: served at rest without
        ending it (see the module doc). A ``fn`` that changes the world must use ``call``.
        """
        if self.in_thread():
            return fn(self.client)
        return self._post(fn, wakes=False).result(timeout)

    def add_hooks(
        self, pre: StepHook | None = None, post: StepHook | None = None, may_rest: bool = False
    ) -> None:
        """Register per-step callbacks (call on the physics thread or before ``start``).

        ``may_rest``: the hooks do nothing by themselves while nothing moves and no command
        runs (the cell's controllers, which say so through a rest check); other hooks (an
        actor's) keep the world from resting while registered.
        """
        if pre is not None:
            self._pre_hooks.append(pre)
        if post is not None:
            self._post_hooks.append(post)
        if not may_rest:
            self._restless += [hook for hook in (pre, post) if hook is not None]

    def remove_hooks(self, pre: StepHook | None = None, post: StepHook | None = None) -> None:
        """Take hooks out again (call on the physics thread); unknown ones are ignored."""
        if pre is not None and pre in self._pre_hooks:
            self._pre_hooks.remove(pre)
        if post is not None and post in self._post_hooks:
            self._post_hooks.remove(post)
        for hook in (pre, post):
            if hook is not None and hook in self._restless:
                self._restless.remove(hook)

    def add_rest_check(self, still: Callable[[], bool]) -> None:
        """A paced loop rests only while ``still()`` (run on the physics thread) says True:
        nothing it knows of moves or has work to do (see the module doc).
        """
        self._rest_checks.append(still)

    def wait_sim(self, seconds: float, timeout: float | None = None) -> bool:
        """Block until simulated time has advanced by ``seconds``; False on a real-time timeout."""
        if self.in_thread():
            raise SimError("wait_sim would block the physics thread")
        event = threading.Event()
        self._schedule(self._time + seconds, event.set, on_close=True)
        return event.wait(timeout)

    def at(self, when: float, fn: Callable[[], None]) -> None:
        """Run ``fn()`` on this thread once simulated time reaches ``when`` (at the next step
        boundary when it already has); dropped when the cell closes first.
        """
        self._schedule(when, fn, on_close=False)
        self.nudge()

    def _schedule(self, when: float, fn: Callable[[], None], on_close: bool) -> None:
        with self._timer_lock:
            heapq.heappush(self._timers, (when, next(self._timer_ids), fn, on_close))

    def advance(self, seconds: float, timeout: float | None = None) -> bool:
        """Lockstep with an engine: let the world step ``seconds`` further (whole steps, at
        least one) and return once it has; until then, and from then until the next call,
        it stands still (calls are served). False on a wall-clock timeout.
        """
        if self.in_thread():
            raise SimError("advance would block the physics thread")
        steps = max(1, round(seconds / self.time_step))
        with self._hold_lock:
            self._lockstep = True
            self._budget += steps
            self._budget_spent.clear()
        self.nudge()
        return self._budget_spent.wait(timeout)

    def release(self) -> None:
        """End the lockstep of :meth:`advance`: the world runs free again."""
        with self._hold_lock:
            self._lockstep = False
            self._budget = 0
            self._budget_spent.set()
        self.nudge()

    def hold(self) -> Callable[[], None]:
        """Stand the world still from now until the returned release is called (once, from
        any thread): the start of a job that must see the world as at the tick that began
        it. See :meth:`standing_still` for a block.
        """
        if self.in_thread():
            raise SimError("hold is for other threads than the physics thread")
        with self._hold_lock:
            self._holds += 1
        # A step already under way when the hold began would still advance the clock: a
        # call served after it means the loop has seen the hold.
        if self.running:
            with contextlib.suppress(SimError):
                self.call(lambda _client: None)
        released = threading.Event()

        def release() -> None:
            if released.is_set():
                return
            released.set()
            with self._hold_lock:
                self._holds -= 1
            self.nudge()  # wake a loop waiting on calls

        return release

    @contextmanager
    def standing_still(self) -> Iterator[None]:
        """Simulated time stands still inside this block (any thread; blocks may nest and
        overlap): the world is not stepped, calls are still served. Lockstep for work that
        takes wall time on another thread (perception), so that the world does not go on
        without it, however loaded the machine.
        """
        if self.in_thread():
            raise SimError("standing_still is for other threads than the physics thread")
        release = self.hold()
        try:
            yield
        finally:
            release()

    @contextmanager
    def sharing(self) -> Iterator[None]:
        """Another thread computes in Python inside this block (perception): the loop hands
        it the GIL after every step meanwhile. Without it, a thread that dropped the GIL for a
        moment (a numpy call) waited for the interpreter's switch interval (5 ms) to get it
        back: a look that takes 1 s alone took 25 s beside a cell stepping as fast as it can.
        """
        with self._hold_lock:
            self._sharers += 1
        try:
            yield
        finally:
            with self._hold_lock:
                self._sharers -= 1

    def add_gate(self, may_step: Callable[[], bool]) -> None:
        """Step the world only while ``may_step()`` (any thread's state; keep it cheap) says
        True: lockstep with another loop, e.g. an engine that must not fall behind. Whoever
        changes what the gate reads calls :meth:`nudge`.
        """
        self._gates.append(may_step)

    def track(self, handle: CommandHandle) -> None:
        """Count ``handle`` as a command in flight until it finishes (see :meth:`waited_on`)."""
        with self._hold_lock:
            self._in_flight += 1

        def finished(_handle: CommandHandle) -> None:
            with self._hold_lock:
                self._in_flight -= 1

        handle.add_done_callback(finished)

    def waited_on(self) -> bool:
        """True while a command is in flight or a thread waits for simulated time: as a gate,
        the world steps only then (a driven cell: each command starts at the step after the
        one the last ended in, however long its sender took to send it).
        """
        return self._in_flight > 0 or bool(self._timers)

    def nudge(self) -> None:
        """Wake a loop that stands still, to look at its gates again (any thread)."""
        if self.running:
            self._queue.put((lambda _client: None, Future(), False))

    # ------------------------------------------------------------------ loop

    def _run(self) -> None:
        try:
            self.client = pybullet.connect(pybullet.DIRECT)
            pybullet.setTimeStep(self.time_step, physicsClientId=self.client)
            self._setup(self.client)
        except Exception as exc:
            self._setup_error = exc
            self._stopping.set()
            self._ready.set()
            self._disconnect()
            return
        self._ready.set()
        try:
            self._loop()
        finally:
            self._fail_pending()
            self._disconnect()

    def _loop(self) -> None:
        wall_start = time.perf_counter()
        sim_start = self._time
        yielded = wall_start
        while not self._stopping.is_set():
            self._drain()
            if (
                self._holds
                or (self._lockstep and self._budget <= 0)
                or not all(gate() for gate in self._gates)
            ):
                self._stand_still()
                continue
            # Driven by an engine (lockstep), every step is one it asked for: no rest.
            if self.speed is not None and not self._lockstep and self._may_rest():
                self._rest(wall_start, sim_start)
                continue
            self._step_once()
            if self._lockstep:
                self._spend_step()
            if self.speed is not None:
                # Time spent serving calls (a camera frame takes 30-300 ms to render) does
                # not pass in the simulated world, as a real camera renders while the world
                # goes on; so the physics does not race to catch up after a render.
                wall = time.perf_counter() - wall_start - self._serving_s
                ahead = (self._time - sim_start) / self.speed - wall
                if ahead > 0.002:
                    self._idle(ahead)
            else:
                now = time.perf_counter()
                if self._sharers or now - yielded > _YIELD_S:
                    time.sleep(0)  # let other Python threads have the GIL
                    yielded = now

    def _quiet(self) -> bool:
        """Nothing asks for steps: no command in flight, no waiter, no restless hook, and
        every rest check says still.
        """
        return (
            not self._in_flight
            and not self._timers
            and not self._restless
            and bool(self._rest_checks)
            and all(still() for still in self._rest_checks)
        )

    def _may_rest(self) -> bool:
        """Whether to rest now (after ``REST_AFTER_S`` of quiet steps; see the module doc)."""
        if self._woken:  # a call at rest may have changed the world: step and look again
            self._woken, self._quiet_steps = False, 0
            return False
        if self._quiet_steps * self.time_step >= REST_AFTER_S:
            return True
        if self.steps % _REST_CHECK_STEPS == 0:
            self._quiet_steps = self._quiet_steps + _REST_CHECK_STEPS if self._quiet() else 0
        return False

    def _rest(self, wall_start: float, sim_start: float) -> None:
        """Nothing moves: serve calls and let simulated time go on with the wall clock,
        without stepping, until a call other than a peek or a rest check ends it.
        """
        if not self.resting:
            self.resting = True
            self.rests += 1
        assert self.speed is not None
        self._serve_one(_REST_WAIT_S)
        wall = time.perf_counter() - wall_start - self._serving_s
        due = int((sim_start + wall * self.speed) / self.time_step) - self.steps
        if due > self._rested_steps:
            self._rested_steps = due
            self._time = (self.steps + self._rested_steps) * self.time_step
            self._fire_timers()
        if self._woken or not self._quiet():
            self.resting = False
            self._woken, self._quiet_steps = False, 0

    def _stand_still(self) -> None:
        """Serve calls without stepping while a block holds time (wall time not simulated)."""
        started, served = time.perf_counter(), self._serving_s
        self._serve_one(0.05)
        self._serving_s = served + (time.perf_counter() - started)

    def _idle(self, seconds: float) -> None:
        """Sleep while ahead of the wall clock, but wake for queued commands."""
        self._serve_one(seconds)

    def _drain(self) -> None:
        while self._serve_one(None):
            pass

    def _serve_one(self, wait: float | None) -> bool:
        """Run one queued call, waiting up to ``wait`` s for one (None: not at all).

        False when none came, or the queue's end mark did (it is taken).
        """
        try:
            item = self._queue.get_nowait() if wait is None else self._queue.get(timeout=wait)
        except queue.Empty:
            return False
        if item is None:
            return False
        fn, future, wakes = item
        if wakes:
            self._woken = True
        self._execute(fn, future)
        return True

    def _execute(self, fn: Callable[[int], Any], future: Future[Any]) -> None:
        if not future.set_running_or_notify_cancel():
            return
        started = time.perf_counter()
        try:
            future.set_result(fn(self.client))
        except BaseException as exc:
            future.set_exception(exc)
        finally:
            self._serving_s += time.perf_counter() - started

    def _step_once(self) -> None:
        self._run_hooks(self._pre_hooks)
        pybullet.stepSimulation(physicsClientId=self.client)
        self.steps += 1
        self._time = (self.steps + self._rested_steps) * self.time_step
        self._run_hooks(self._post_hooks)
        self._fire_timers()

    def _spend_step(self) -> None:
        with self._hold_lock:
            self._budget -= 1
            if self._budget <= 0:
                self._budget_spent.set()

    def _run_hooks(self, hooks: list[StepHook]) -> None:
        for hook in hooks:
            try:
                hook(self._time)
            except Exception:
                _log.exception("step hook %r raised", hook)

    def _fire_timers(self) -> None:
        if not self._timers:
            return
        due = []
        with self._timer_lock:
            while self._timers and self._timers[0][0] <= self._time + 1e-9:
                due.append(heapq.heappop(self._timers)[2])
        for fn in due:  # outside the lock: a handed-over result may schedule another
            try:
                fn()
            except Exception:
                _log.exception("timer %r raised", fn)

    def _fail_pending(self) -> None:
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                break
            if item is not None and item[1].set_running_or_notify_cancel():
                item[1].set_exception(SimError("the simulated cell was closed"))
        with self._timer_lock:
            closing = [fn for _, _, fn, on_close in self._timers if on_close]
            self._timers.clear()
        for fn in closing:  # waiters wake (their wait says the time did not come)
            fn()
        self._budget_spent.set()

    def _disconnect(self) -> None:
        if self.client >= 0:
            try:
                pybullet.disconnect(physicsClientId=self.client)
            except pybullet.error:
                _log.warning("pybullet disconnect failed")
