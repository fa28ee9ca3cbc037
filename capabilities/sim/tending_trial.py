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
- With ``lead`` the world never runs more than ``lead`` simulated seconds ahead of the
  engine's last tick (a gate of the physics thread): with a lockstep session (time stands
  still while perception computes) a run as fast as possible then reacts as a 50 Hz
  controller would, however loaded the machine.
- The trial ends once the bender released its last part and everything settled (every
  part in a tote or taken away), or ``tail`` simulated seconds after that last release.

Ground truth (the bender's events, object poses) is read only to score and to play the
operator, never by the plan.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from pathlib import Path

from capabilities.base import CapabilityRegistry
from capabilities.bullet import pybullet as p
from capabilities.faults import hold_check
from capabilities.sim.errors import SimError
from capabilities.sim.session import SimCellSession
from capabilities.sim.tending_score import TrialCounters, loose_things, lost_parts, score_trial
from engine.build import build_tree
from engine.events import Event, RunHeld, StatusChanged
from engine.executor import Executor
from engine.files import load_plan
from engine.hold import Hold
from engine.status import Status
from engine.validation import has_errors, validate_plan

__all__ = ["OperatorModel", "TendingTrial", "TrialError"]

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


class TendingTrial:
    """One trial of ``plan`` on ``session`` (whose scene has a bender not started yet).

    Args:
        session: a session made with ``start_actors=False``.
        plan: the plan file.
        operator: who answers the plan's calls.
        rate_hz: the executor's tick rate.
        lead: simulated seconds the world may run ahead of the engine (None: no bound).

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
        lead: float | None = None,
    ) -> None:
        if session.bender is None:
            raise TrialError(f"the scene {session.scene.name!r} has no wire bender")
        self.session = session
        self.operator = operator or OperatorModel()
        self.calls: list[float] = []
        self.stops: list[str] = []
        self.failures: list[tuple[float, str]] = []
        self._lock = threading.Lock()
        self._pending: list[tuple[float, bool]] = []  # when the operator resets; press?
        self._removed: set[int] = set()
        self._last_failure = ""
        self._engine_at: float | None = None  # simulated time of the engine's last tick
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
        self.executor = Executor(tree, rate_hz, [self._heard], hold=self._before_tick)
        if lead is not None:
            bound = lead
            session.sim.add_gate(lambda: self._lag() <= bound)

    # ------------------------------------------------------------------ the engine

    def _before_tick(self) -> Hold | None:
        """The executor's hold check, asked before every tick: the engine is here now."""
        self._engine_at = self.session.clock()
        self.session.sim.nudge()
        return self._cell_hold() if self._cell_hold is not None else None

    def _lag(self) -> float:
        """How far the world is ahead of the engine (0 before it starts, once it ended)."""
        at = self._engine_at
        if at is None or self.executor.result is not None:
            return 0.0
        return self.session.clock() - at

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
            if self.operator.present:
                self._pending.append((now + self.operator.reset_s, press))

    # ------------------------------------------------------------------ the operator

    def _operate(self) -> None:
        """Reset the cell and press Continue for each call whose reset time has come."""
        now = self.session.clock()
        with self._lock:
            due = [press for t, press in self._pending if t <= now]
            self._pending = [(t, press) for t, press in self._pending if t > now]
        for press in due:
            self._clear_cell()
            if self.session.hold_reason():
                self.session.clear()  # on the pendant: unlocks once the delay allows
            if press:
                self.session.operator.press("continue")

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
        """Nothing loose, nothing held, no call of the operator open."""
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
        deadline = None if wall_timeout is None else time.monotonic() + wall_timeout
        self._engine_at = self.session.clock()  # the gate holds until the engine ticks
        self.executor.start()
        try:
            self._run_until_done(tail, deadline, until)
        finally:
            self.executor.stop("trial over")
            self.executor.wait(10.0)
            self._engine_at = None  # no engine any more: the world goes on
        self.session.sim.wait_sim(SETTLE)
        return self.score()

    def _run_until_done(self, tail: float, deadline: float | None, until: float | None) -> None:
        session, bender = self.session, self.session.bender
        assert bender is not None
        while self.executor.result is None:
            if deadline is not None and time.monotonic() > deadline:
                raise TrialError(f"the trial ran out of wall time at {session.clock():.0f} s")
            session.sim.wait_sim(POLL)
            self._operate()
            start = bender.start_time
            if until is not None and start is not None and session.clock() - start >= until:
                return
            released = bender.produced()
            if not bender.plan or len(released) < len(bender.plan):
                continue
            since = session.clock() - released[-1].time
            if since >= tail or (since > SETTLE and self._settled()):
                return

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

    def lost(self) -> list[dict[str, object]]:
        """Each lost part's fault and whereabouts, with the failures around it (ground truth,
        for the bench's report): the failures from 5 s before its release to 40 s after.
        """
        session, bender = self.session, self.session.bender
        assert bender is not None
        report = session.sim.call(
            lambda client: lost_parts(client, bender, session.scene, self._removed)
        )
        start = bender.start_time or 0.0
        for part in report:
            at = float(part["released"])
            part["released"] = round(at - start, 1)
            part["failures"] = [
                f"{t - start:.1f} s {what}" for t, what in self.failures if at - 5 <= t <= at + 40
            ]
        return report
