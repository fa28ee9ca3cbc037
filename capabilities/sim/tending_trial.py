"""A trial of a wire-bender tending plan on the simulated ``tending`` cell (paper, V-B).

:class:`TendingTrial` runs a plan (the paper's ``tending_paper.costar.json`` or ours) through
the engine on a :class:`SimCellSession` of a scene with a bender, for the bender's parts (or
its first N), and scores it as Table I does (``tending_score``). As on site:

- The bender starts when the robot first watches it (the first occupancy operation runs):
  setting up the run costs none of the bender's parts.
- An operator (:class:`OperatorModel`) answers a plan that waits for one (a
  ``collaboration.wait_for_button``) or a run held by a protective stop its plan does not
  catch: after ``reset_s`` simulated seconds (the paper: "the robot would need to be stopped
  and reset ... the bender kept producing parts") the operator clears away what lies loose in
  the cell (parts and pieces at the exit or dropped: lost), unlocks a protective stop and
  presses Continue.
- The session runs in lockstep (``SimCellSession(lockstep=..., still_until_run=True)``):
  the world goes on only with the engine's ticks, perception holds it, and the run begins at
  simulated time 0. What the trial does happens at set simulated times on the engine or the
  physics thread, never when a thread of its own wakes up: the bender starts at the tick its
  first watch began (an inline listener), the operator acts on the physics thread
  ``reset_s`` after the tick that called, and the trial looks at the cell there every
  ``POLL`` s. The same plan, scene, seed and faults give the same trial, however loaded the
  machine.
- The trial ends once the bender released its last part and everything settled (every
  part in a tote or taken away), or ``tail`` simulated seconds after that last release; it
  is scored ``SETTLE`` s later.

Ground truth (the bender's events, object poses) is read only to score and to play the
operator, never by the plan.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capabilities.base import CapabilityRegistry
from capabilities.bullet import pybullet as p
from capabilities.faults import hold_check
from capabilities.run_sampler import record_samplers
from capabilities.sim.bender_spec import FaultModel
from capabilities.sim.errors import SimError
from capabilities.sim.session import PERCEPTION_S, SimCellSession
from capabilities.sim.tending_score import TrialCounters, loose_things, lost_parts, score_trial
from engine.build import build_tree
from engine.events import Event, RunHeld, StatusChanged
from engine.executor import Executor
from engine.files import load_plan
from engine.hold import Hold
from engine.status import Status
from engine.trace import TraceRecorder
from engine.validation import has_errors, validate_plan

__all__ = ["OperatorModel", "TendingTrial", "TrialError", "trial_session"]

OPERATOR_OPS = frozenset({"collaboration.wait_for_button"})
WATCH_PREFIX = "occupancy."  # the first of these to run starts the bender
POLL = 0.5  # simulated seconds between the trial's looks at the cell
SETTLE = 1.0  # simulated seconds things get to settle before the score


class TrialError(SimError):
    """A trial could not run (no bender, an invalid plan, out of wall time)."""


@dataclass(frozen=True)
class OperatorModel:
    """The person who resets the cell when the plan stops for them.

    Attributes:
        reset_s: simulated seconds from the plan's call until Continue (walking over,
            clearing the exit, pressing the button); the bender goes on meanwhile.
        present: False: nobody answers (a plan that calls stays stopped).
    """

    reset_s: float = 30.0
    present: bool = True


def trial_session(
    scene: str | Path, seed: int, speed: float | None = None, faults: FaultModel | None = None
) -> SimCellSession:
    """A session for a :class:`TendingTrial`: in lockstep from simulated time 0, the bender
    waiting for the plan's first watch; as fast as it can (``speed`` None) or paced.
    """
    return SimCellSession(
        scene,
        seed,
        speed=speed,
        faults=faults,
        start_actors=False,
        lockstep=PERCEPTION_S,
        still_until_run=True,
    )


class TendingTrial:
    """One trial of ``plan`` on ``session`` (whose scene has a bender not started yet).

    Args:
        session: a session in lockstep from simulated time 0 with the bender not started:
            :func:`trial_session`.
        plan: the plan file.
        operator: who answers the plan's calls.
        rate_hz: the executor's tick rate.
        record: keep the run's record in this file, as `costar run` does (None: none).

    Attributes:
        calls: simulated times at which the plan (or a held run) called the operator.
        stops: for each call, the last operation that failed before it ("" if none), or
            why the run was held.
        failures: every operation that failed: (simulated time, "label: message").
    """

    def __init__(
        self,
        session: SimCellSession,
        plan: Path,
        operator: OperatorModel | None = None,
        rate_hz: float = 50.0,
        record: Path | None = None,
    ) -> None:
        if session.bender is None:
            raise TrialError(f"the scene {session.scene.name!r} has no wire bender")
        lockstep = session.run_lockstep()
        if lockstep is None:
            raise TrialError("a trial needs a session in lockstep (SimCellSession(lockstep=...))")
        self.session = session
        self.operator = operator or OperatorModel()
        self.calls: list[float] = []
        self.stops: list[str] = []
        self.failures: list[tuple[float, str]] = []
        self._lock = threading.Lock()
        self._pending = 0  # operator calls not answered yet
        self._removed: set[int] = set()
        self._last_failure = ""
        self._over = threading.Event()  # the trial is over: the engine stops at its next tick
        self._scored: Future[tuple[TrialCounters, list[dict[str, Any]]]] = Future()
        self._lost: list[dict[str, Any]] | None = None  # lost parts when scored
        registry = CapabilityRegistry(cell=session)
        spec = load_plan(plan, registry.aliases())
        problems = validate_plan(spec, registry)
        if has_errors(problems):
            errors = "; ".join(str(x) for x in problems if x.severity == "error")
            raise TrialError(f"{plan}: the plan is not valid: {errors}")
        # (label, operation) by node id: the plan's own and its subtrees' (an instance's
        # nodes run as "<instance id>/<node id>"; see node()).
        self._nodes = {node.id: (node.label, node.op or "") for _, node in spec.walk()}
        for sub in spec.subtrees:
            for _, node in sub.tree.walk():
                self._nodes.setdefault(node.id, (f"{sub.name}/{node.label}", node.op or ""))
        tree = build_tree(spec, registry, clock=session.clock)
        self._cell_hold = hold_check(session)
        listeners: list[Callable[[Event], None]] = []
        if record is not None:
            recorder = TraceRecorder(record, spec, {"cell": "sim", "scene": "tending"})
            listeners = [recorder, *record_samplers(session, recorder)]
        self.executor = Executor(
            tree,
            rate_hz,
            listeners,
            hold=self._before_tick,
            lockstep=lockstep,
            inline=[self._heard],
        )

    # ------------------------------------------------------------------ the engine

    def _before_tick(self) -> Hold | None:
        """The executor's hold check, asked before every tick (engine thread, the world
        standing still): the trial ends here once it is over, at the same tick every run.
        """
        if self._over.is_set():
            self.executor.stop("trial over")
        return self._cell_hold() if self._cell_hold is not None else None

    def ended(self) -> str:
        """How the plan's run ended ("" while it runs or when the trial stopped it)."""
        result = self.executor.result
        if result is None or result.reason == "trial over":
            return ""
        return f"{result.status.value} ({result.reason}): {result.message}"

    # ------------------------------------------------------------------ the plan's events

    def node(self, node_id: str) -> tuple[str, str]:
        """(label, operation) of a running node ("SUBTREE/label" inside an instance)."""
        return self._nodes.get(node_id.rsplit("/", 1)[-1], ("", ""))

    def _heard(self, event: Event) -> None:
        """An inline listener: on the engine thread, at the tick of the event (the world
        stands still meanwhile, so "now" is the tick's simulated time).
        """
        if isinstance(event, RunHeld) and event.reason:
            self._call(f"held: {event.reason}", press=False)
        if not isinstance(event, StatusChanged):
            return
        label, op = self.node(event.node_id)
        if event.new is Status.FAILURE and op and op not in OPERATOR_OPS:
            self._last_failure = f"{label}: {event.message}"
            self.failures.append((round(self.session.clock(), 1), self._last_failure))
        if event.new is not Status.RUNNING:
            return
        if op.startswith(WATCH_PREFIX):
            self.session.start_actors()  # from the first watch on; later calls do nothing
        if op in OPERATOR_OPS:
            self._call(self._last_failure, press=True)

    def _call(self, why: str, press: bool) -> None:
        """The operator is called now (comes ``reset_s`` later if present); ``press``: the
        plan waits for Continue (a held run does not: a press would wait for the next).
        """
        now = self.session.clock()
        with self._lock:
            self.calls.append(now)
            self.stops.append(why)
            if not self.operator.present:
                return
            self._pending += 1
        self.session.sim.at(now + self.operator.reset_s, lambda: self._reset(press))

    # ------------------------------------------------------------------ the operator

    def _reset(self, press: bool) -> None:
        """On the physics thread, ``reset_s`` after a call: clear the cell, unlock a
        protective stop and press Continue if the plan waits for it.
        """
        self._clear_cell()
        if self.session.hold_reason():
            self.session.clear()  # on the pendant: unlocks once the delay allows
        if press:
            self.session.operator.press("continue", "the simulated operator")
        with self._lock:
            self._pending -= 1

    def _clear_cell(self) -> None:
        """Take away every loose part and piece (as the operator does: they are lost)."""
        session, bender = self.session, self.session.bender
        assert bender is not None

        def clear(client: int) -> None:
            parts, pieces = loose_things(client, bender, session.scene)
            for name in parts:
                session.scene.remove(client, name)
            for body in pieces:
                p.removeBody(body, physicsClientId=client)
                self._removed.add(body)

        session.sim.call(clear)

    def _settled(self) -> bool:
        """Nothing loose, nothing held, no call of the operator open (physics thread)."""
        session, bender = self.session, self.session.bender
        assert bender is not None
        with self._lock:
            if self._pending:
                return False
        if session.sim.gripper.is_holding():
            return False

        def loose(client: int) -> bool:
            parts, pieces = loose_things(client, bender, session.scene)
            return bool(parts or [b for b in pieces if b not in self._removed])

        return not session.sim.call(loose)

    # ------------------------------------------------------------------ the run

    def run(
        self,
        parts: int | None = None,
        tail: float = 60.0,
        wall_timeout: float | None = None,
        until: float | None = None,
    ) -> TrialCounters:
        """Run the trial and score it.

        Args:
            parts: only the bender's first ``parts`` parts (None: all of its plan).
            tail: simulated seconds after the last release at which the trial ends anyway.
            wall_timeout: wall seconds after which TrialError is raised (None: no bound).
            until: end this many simulated seconds after the bender started, whatever is
                left to do (a soak).
        """
        bender = self.session.bender
        assert bender is not None
        if parts is not None:
            if bender.start_time is not None:
                raise TrialError("the bender already started: its parts are set")
            bender.plan = bender.plan[:parts]
        sim = self.session.sim
        sim.at(sim.time() + POLL, lambda: self._look(tail, until))
        self.executor.start()
        try:
            counters, self._lost = self._scored.result(wall_timeout)
        except FutureTimeout:
            at = self.session.clock()
            raise TrialError(f"the trial ran out of wall time at {at:.0f} s") from None
        finally:
            self.executor.stop("trial over")
            self.executor.wait(10.0)
        return counters

    def _look(self, tail: float, until: float | None) -> None:
        """On the physics thread every ``POLL`` s: is the trial over? Then it is scored
        ``SETTLE`` s later, there too.
        """
        if not self._is_over(tail, until):
            self.session.sim.at(self.session.clock() + POLL, lambda: self._look(tail, until))
            return
        self._over.set()
        self.session.sim.at(self.session.clock() + SETTLE, self._score_now)

    def _is_over(self, tail: float, until: float | None) -> bool:
        bender = self.session.bender
        assert bender is not None
        if self.executor.result is not None:  # the plan ended: nothing more will happen
            return True
        now, start = self.session.clock(), bender.start_time
        if until is not None and start is not None and now - start >= until:
            return True
        released = bender.produced()
        if not bender.plan or len(released) < len(bender.plan):
            return False
        since = now - released[-1].time
        return since >= tail or (since > SETTLE and self._settled())

    def _score_now(self) -> None:
        try:
            self._scored.set_result((self.score(), self._lost_now()))
        except Exception as exc:  # a score that cannot be made ends the trial with it
            self._scored.set_exception(exc)

    def score(self) -> TrialCounters:
        """Table I's counters now (ground truth)."""
        session, bender = self.session, self.session.bender
        assert bender is not None
        start = bender.start_time or 0.0
        with self._lock:
            calls = len(self.calls)

        def count(client: int) -> TrialCounters:
            elapsed = session.sim.time() - start
            return score_trial(client, bender, session.scene, self._removed, calls, elapsed)

        return session.sim.call(count)

    def _lost_now(self) -> list[dict[str, Any]]:
        session, bender = self.session, self.session.bender
        assert bender is not None
        return session.sim.call(
            lambda client: lost_parts(client, bender, session.scene, self._removed)
        )

    def lost(self) -> list[dict[str, Any]]:
        """Each lost part's fault and whereabouts when the trial was scored (now, before),
        with the failures around it (ground truth, for the bench's report): the failures
        from 5 s before its release to 40 s after.
        """
        bender = self.session.bender
        assert bender is not None
        report = [
            dict(part) for part in (self._lost if self._lost is not None else self._lost_now())
        ]
        start = bender.start_time or 0.0
        for part in report:
            at = float(part["released"])
            part["released"] = round(at - start, 1)
            part["failures"] = [
                f"{t - start:.1f} s {what}" for t, what in self.failures if at - 5 <= t <= at + 40
            ]
        return report
