"""RunController: runs the document's plan on the session's cell and reports in Qt signals.

The executor ticks on its own thread and delivers events on its dispatcher thread; those
go into an :class:`~instructor_app.runtime.pump.EventPump` that a QTimer drains in the GUI
thread about 30 times a second, so the canvas gets at most one status per node per frame.
No method here waits for the engine: ``stop()`` asks the executor to stop and the run ends
when its RunFinished event comes through the pump.
"""

from __future__ import annotations

import copy
import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QObject, QTimer, Signal

from capabilities.cell_features import ReportsStatus, lockstep_of
from capabilities.faults import hold_check
from capabilities.run_sampler import record_samplers
from engine.blackboard import OPERATOR, Blackboard, BlackboardEntry, BlackboardError
from engine.build import BuildError, build_tree
from engine.events import Listener, RunFinished
from engine.executor import Executor, ExecutorState
from engine.failure_words import failed_words
from engine.run_records import RunRecordError, new_record_path, prune_records, runs_folder
from engine.run_report import FailureLog, RootCause
from engine.spec import PlanSpec
from engine.status import RUNNING, Status
from engine.trace import TraceRecorder
from engine.tree import BehaviorTree
from engine.validation import ERROR, Problem, has_errors, validate_plan
from instructor_app.document.editing import PlanDocument
from instructor_app.runtime.debugging import RunDebugging
from instructor_app.runtime.pump import Batch, EventPump, failure_text
from instructor_app.runtime.session import CellSession

if TYPE_CHECKING:
    from capabilities.groot2.publisher import Groot2Publisher

__all__ = ["RunController", "RunOutcome"]


@dataclass(frozen=True)
class RunOutcome:
    """How a run ended.

    Attributes:
        event: the executor's RunFinished event (status, reason, ticks, message).
        failed_node: the node of the plan the run's failure started at ("" if none; the
            instance when it started inside one).
        failure_message: why it failed there ("grasp_failed: nothing between the fingers").
        statuses: the last status seen of every node of the plan that ran.
        cause: the root cause of the run's failure (None when it did not fail): the node it
            started at, its error type and message, how often, the nodes that passed it up.
        on_the_way: the other root causes: failures the run carried on past (with the node
            that caught each) and fallbacks that failed too.
    """

    event: RunFinished
    failed_node: str
    failure_message: str
    statuses: dict[str, Status]
    cause: RootCause | None = None
    on_the_way: tuple[RootCause, ...] = ()

    @property
    def status(self) -> Status:
        return self.event.status


class RunController(QObject):
    """Run, pause, step and stop the plan of ``document`` on the cell of ``session``.

    Args:
        document: the open plan (a snapshot of it is taken when a run starts).
        session: the cell and its registry.
        rate_hz: executor tick rate.
        drain_hz: how often queued events reach the GUI.

    Signals:
        statuses_changed(dict): node id -> Status, only the nodes changed since last time.
        blackboard_written(str, object): a blackboard key and its newest value.
        entries_written(list): the newest :class:`BlackboardEntry` of each key written since
            the last drain (its ``time`` in seconds since the run started); when a run
            starts, every entry it starts with (the plan's parameters, tick 0).
        log_message(str, str): text and level ("info", "warning", "error").
        run_state_changed(object): the run's ExecutorState (READY before the first run).
        run_starting(): Run or Step was asked for, before the cell is reset and the plan is
            checked (on the GUI thread: a teaching Freedrive is turned off here).
        running_nodes_changed(list): ids of the nodes now RUNNING, in plan order.
        run_finished(object): a :class:`RunOutcome`.
        run_refused(list): the validation problems (or a build error) that kept it from starting.
        failure_changed(str, str): the failing node and what to say of it: while the run goes,
            the deepest failing node, "look for cup failed (not_found): no cup"; when it
            failed, the node its failure started at and the root cause, "grasp CUP failed 4
            times (grasp_failed): nothing between the fingers; passed up by ..." ("" "": none).
        failures_described(object): node id -> "error type: message" of the nodes that failed;
            when the run ends, the node each root cause started at -> "error type: message (4
            times); passed up by ...; caught by ...".
        hold_changed(str, str): the cell held the run (why, and what to show: "held: protective
            stop, clear it on the pendant or press Unlock protective stop") or let it go on
            ("" ""). The nodes that were running stay shown RUNNING while it is held.
        inner_statuses_changed(object): runtime id ("instance/inner") -> Status inside subtree
            instances; None when a new run starts.
        nodes_halted(list): ids of the nodes that were running when the run was stopped (or
            ended by an error): halted, they keep their last status.
        run_paused(str, str): the run paused by itself (a breakpoint, a step, a run to a
            node): the plan node it paused at (the instance, inside one) and why, in words.

    Attributes:
        debugging: the operator's breakpoints, skipped nodes and forced results.
    """

    # object, not dict: a dict signal goes through QVariantMap and turns Status into str.
    statuses_changed = Signal(object)
    blackboard_written = Signal(str, object)
    entries_written = Signal(list)
    log_message = Signal(str, str)
    run_state_changed = Signal(object)
    run_starting = Signal()
    running_nodes_changed = Signal(list)
    run_finished = Signal(object)
    run_refused = Signal(list)
    # runtime id ("instance/inner") -> Status of nodes inside subtree instances; None: a new run
    inner_statuses_changed = Signal(object)
    failure_changed = Signal(str, str)
    failures_described = Signal(object)
    hold_changed = Signal(str, str)
    nodes_halted = Signal(list)
    run_paused = Signal(str, str)

    def __init__(
        self,
        document: PlanDocument,
        session: CellSession,
        rate_hz: float = 20.0,
        drain_hz: float = 30.0,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.session = session
        self.rate_hz = rate_hz
        self._pump = EventPump()
        self._timer = QTimer(self)
        self._timer.setInterval(max(1, round(1000 / drain_hz)))
        self._timer.timeout.connect(self._drain)
        self._executor: Executor | None = None
        self._failures: FailureLog | None = None
        self._state: ExecutorState = ExecutorState.READY
        self._plan: PlanSpec | None = None
        self._order: dict[str, tuple[int, int]] = {}  # node id -> (depth, plan order)
        self._statuses: dict[str, Status] = {}
        self._messages: dict[str, str] = {}
        self._said: dict[str, str] = {}  # node id -> "look for cup failed (not_found): no cup"
        self._last_board: Blackboard | None = None  # the last run's values, for a resume
        self._started_at = 0.0  # time.monotonic() when the run started
        self._running: list[str] = []
        self._failure: tuple[str, str] = ("", "")
        self._stopping = False  # a stop was asked: the halt's IDLE resets are not shown
        self._held = ""  # why the cell holds the run ("" when it does not)
        self.last_record: Path | None = None  # the record of the last run started
        self.runs_setting = ""  # the runs folder of the settings ("": the default)
        self._idled: set[str] = set()  # nodes that went RUNNING -> IDLE at the last drain
        self._groot2_port: int | None = None  # publish runs for Groot2 on it (None: do not)
        self._groot2: Groot2Publisher | None = None  # serving, once a run was published
        self.debugging = RunDebugging(self)

    # ------------------------------------------------------------------ state

    @property
    def state(self) -> ExecutorState:
        return self._state

    @property
    def is_running(self) -> bool:
        """True from start until the RunFinished event was handled (paused counts)."""
        return self._state in (ExecutorState.RUNNING, ExecutorState.PAUSED)

    @property
    def held(self) -> str:
        """Why the cell holds the run now ("" when it does not)."""
        return self._held

    @property
    def statuses(self) -> dict[str, Status]:
        """The last status seen of each node of the current (or last) run."""
        return dict(self._statuses)

    # ------------------------------------------------------------------ control

    def run(self) -> bool:
        """Start a run (resume when paused); False when the plan was refused or one runs."""
        if self._state == ExecutorState.PAUSED:
            self.resume()
            return True
        if self._state == ExecutorState.RUNNING:
            return False
        return self._start(paused=False)

    def pause(self) -> None:
        if self._executor is not None and self._state == ExecutorState.RUNNING:
            self._executor.pause()
            self._set_state(ExecutorState.PAUSED)

    def resume(self) -> None:
        if self._executor is not None and self._state == ExecutorState.PAUSED:
            self._executor.resume()
            self._set_state(ExecutorState.RUNNING)

    def step(self) -> None:
        """One tick: starts a paused run when idle, pauses a running one first."""
        executor = self._paused_run()
        if executor is not None:
            executor.step()

    def _paused_run(self) -> Executor | None:
        """The run, paused: a paused run started when idle, a running one paused first
        (None when none can start).
        """
        if not self.is_running:
            if not self._start(paused=True):
                return None
        elif self._state == ExecutorState.RUNNING:
            self.pause()
        assert self._executor is not None
        return self._executor

    def set_entry(self, key: str, value: Any) -> None:
        """Set a named parameter of the paused run (the engine writes it between ticks, as
        the operator's); it comes back through ``entries_written``.

        Raises BlackboardError (naming the entry and its type) for a value of another type,
        RuntimeError when no run is paused.
        """
        if self._executor is None or self._state != ExecutorState.PAUSED:
            raise RuntimeError(f"{key} can be set only while a run is paused")
        self._executor.set_entry(key, value, OPERATOR)

    def label(self, node_id: str) -> str:
        """What the Instructor calls a node of the current run (runtime ids inside instances
        too: "greet > say"); the id itself when the plan has no such node.
        """
        return self._label(node_id)

    def step_next(self) -> None:
        """Run to the next status change of any node and pause there (starts a paused run
        when idle).
        """
        self._debug_go(lambda executor: executor.step_next())

    def step_over(self) -> None:
        """Run the node the run paused at to its end, and pause there."""
        self._debug_go(lambda executor: executor.step_over())

    def run_to(self, node_id: str) -> None:
        """Run on until ``node_id`` is about to start, and pause there (starts a run when
        idle).
        """
        self._debug_go(lambda executor: executor.run_to(node_id))

    def _debug_go(self, go: Callable[[Executor], None]) -> None:
        executor = self._paused_run()
        if executor is not None:
            go(executor)
            self._set_state(ExecutorState.RUNNING)

    def stop(self) -> None:
        """Halt what runs (an arm in motion stops); the run ends via run_finished.

        The nodes keep the statuses they had when stopped (the halt resets them to IDLE in the
        engine; those resets are not shown) until the next run starts.
        """
        if self._executor is not None and self.is_running:
            self._stopping = True
            # timeout=0: never join the engine thread from the GUI thread.
            self._executor.stop("stopped", timeout=0)

    def shutdown(self, timeout: float = 2.0) -> None:
        """Stop and wait (bounded) for the engine: for closing the application only."""
        self.set_groot2_port(None)
        executor = self._executor
        if executor is None:
            return
        executor.stop("stopped", timeout=timeout)
        executor.wait(timeout)
        self._drain()
        self._timer.stop()

    # ------------------------------------------------------------------ Groot2

    @property
    def groot2_port(self) -> int | None:
        """The port runs are published on for Groot2 (None: they are not)."""
        return self._groot2_port

    def set_groot2_port(self, port: int | None) -> None:
        """Publish the runs for Groot2 on ``port`` from the next run on (None: stop now).

        The publisher (ZeroMQ on 127.0.0.1, ``port`` and ``port + 1``) stays up between runs,
        showing the last run, so Groot2 stays connected; each run is a new tree to it.
        """
        if self._groot2 is not None and port != self._groot2.port:
            self._groot2.close()
            self._groot2 = None
        self._groot2_port = port

    def _groot2_monitor(self, plan: PlanSpec, tree: BehaviorTree) -> Listener | None:
        """The listener that publishes this run for Groot2, when asked to; a problem is
        logged and the run goes on without it.
        """
        if self._groot2_port is None:
            return None
        from capabilities.groot2.protocol import Groot2Monitor
        from capabilities.groot2.publisher import Groot2Error, Groot2Publisher
        from engine.btcpp import XmlExportError
        from engine.btcpp.runtime import loaded_tree

        manifests = {m.id: m for m in self.session.registry.manifests()}
        try:
            monitor = Groot2Monitor(loaded_tree(plan, manifests), tree.blackboard.snapshot())
            if self._groot2 is None:
                self._groot2 = Groot2Publisher(monitor, self._groot2_port)
                self.log_message.emit(
                    f"Groot2: publishing the runs on {self._groot2.address}", "info"
                )
            else:
                self._groot2.serve(monitor)
        except (Groot2Error, XmlExportError) as exc:
            self.log_message.emit(f"Groot2: not published: {exc}", "warning")
            return None
        return monitor

    # ------------------------------------------------------------------ starting

    def reset_cell(self, scene: str = "") -> bool:
        """Put the cell back to its start (see CellSession.reset); False while a plan runs
        or a cell opens. ``scene``: the simulated scene to start from (the plan's own; "":
        the session's default).
        """
        if self.is_running or self.session.opening:
            return False
        self.session.scene = scene or self.session.default_scene
        self.session.reset()
        self.log_message.emit(f"The {self.session.name} cell was reset", "info")
        return True

    def resume_from(self, node_id: str) -> bool:
        """Run again from ``node_id`` after a run stopped or finished (the operator fixed it).

        The cell is not reset; the nodes before it in the sequences on its path count as done
        (``BehaviorTree.start_at``) and the last run's parameter values are kept, so what
        those nodes found is there. False when a run is going or the plan was refused.
        """
        if self.is_running:
            return False
        return self._start(paused=False, start_at=node_id)

    def _start(self, paused: bool, start_at: str | None = None) -> bool:
        if self.session.opening:  # the registry is about to change under the plan
            message = f"the {self.session.opening} cell is still opening; run when it is ready"
            self.run_refused.emit([Problem(ERROR, None, "plan", None, message)])
            return False
        self.run_starting.emit()
        plan = copy.deepcopy(self.document.plan)  # edits during the run do not reach it
        self._started_at = time.monotonic()
        if plan.reset_cell and start_at is None:
            self.reset_cell(plan.scene)
        registry = self.session.registry
        problems = validate_plan(plan, registry)
        if has_errors(problems):
            self.run_refused.emit([p for p in problems if p.severity == ERROR])
            return False
        try:
            tree = build_tree(plan, registry, clock=self.session.clock())
        except BuildError as exc:
            self.run_refused.emit([Problem(ERROR, None, exc.path, None, str(exc))])
            return False
        done = self._resume_at(tree, start_at) if start_at else {}
        if done is None:
            return False
        for problem in problems:
            self.log_message.emit(str(problem), "warning")
        self._last_board = tree.blackboard
        self._reset_run(plan)
        self._statuses.update({k: v for k, v in done.items() if k in self._order})
        hold = hold_check(self.session.cell)  # a robot's stops (held, or thrown to a Catch)
        self._failures = FailureLog(plan)  # on the dispatcher thread, read when the run ends
        recorder = self._recorder(plan)  # first: what the views show is already recorded
        # On the simulated cell the engine drives the world, paced to real time: the run
        # is the one `costar run` gives for the same plan, scene and seed.
        listeners: list[Listener] = [*recorder, self._pump.put, self._failures]
        groot2 = self._groot2_monitor(plan, tree)
        if groot2 is not None:
            listeners.append(groot2)
        self._executor = Executor(
            tree,
            self.rate_hz,
            listeners,
            plan_name=plan.name,
            hold=hold,
            lockstep=lockstep_of(self.session.cell),
            debugger=self.debugging.debugger(),
        )
        if groot2 is not None:  # Groot2's breakpoints pause this run
            from capabilities.groot2.hooks import Groot2Hooks
            from capabilities.groot2.protocol import Groot2Monitor

            assert isinstance(groot2, Groot2Monitor)
            executor = self._executor
            groot2.hooks = Groot2Hooks(groot2.tree.uids, executor.debugger, executor.resume)
        self._executor.start(paused=paused)
        self._timer.start()
        self._set_state(ExecutorState.PAUSED if paused else ExecutorState.RUNNING)
        # Every node starts the run grey (IDLE), also those the run never reaches; sent after
        # the state change, on which the views clear the last run's colours.
        self.statuses_changed.emit(dict(self._statuses))
        self.entries_written.emit([self._since_start(e) for e in tree.blackboard.entries()])
        if start_at:
            self.log_message.emit(
                f"Run of {plan.name or 'the plan'} resumed from {self._label(start_at)} "
                f"({len(done)} nodes before it counted as done)",
                "info",
            )
        else:
            self.log_message.emit(f"Run of {plan.name or 'the plan'} started", "info")
        return True

    def runs_folder(self) -> Path:
        """Where run records go: $COSTAR_RUNS, else the setting, else the user's data folder."""
        return runs_folder(setting=self.runs_setting or None)

    def _recorder(self, plan: PlanSpec) -> list[Listener]:
        """This run's record in the runs folder (:meth:`runs_folder`; the oldest removed
        past its size limit), as `costar run` keeps one; none when it cannot be written
        (said in the Log: the run goes on).
        """
        folder = self.runs_folder()
        try:
            path = new_record_path(folder, plan.name)
            recorder = TraceRecorder(path, plan)
        except (RunRecordError, OSError) as exc:
            self.log_message.emit(f"This run keeps no record: {exc}", "warning")
            return []
        prune_records(folder, keep=path)
        self.last_record = path
        return [recorder, *record_samplers(self.session.cell, recorder)]

    def _resume_at(self, tree: BehaviorTree, node_id: str) -> dict[str, Status] | None:
        """Mark the nodes before ``node_id`` done and carry the last run's values over."""
        try:
            done = tree.start_at(node_id)
        except KeyError:
            message = f"there is no node {node_id!r} to resume from"
            self.run_refused.emit([Problem(ERROR, None, node_id, None, message)])
            return None
        if self._last_board is not None:
            for key, value in self._last_board.snapshot().items():
                try:
                    tree.blackboard.set(key, value, "resume")
                except BlackboardError:  # the plan now declares it of another type
                    continue
        return done

    def _reset_run(self, plan: PlanSpec) -> None:
        self._plan = plan
        self._order = _depth_order(plan)
        self._pump.drain()  # leftovers of an earlier run must not colour this one
        self._statuses, self._messages, self._running = {}, {}, []
        self._said = {}
        self._stopping = False
        self._held, self._idled = "", set()
        self._set_failure("", "")
        self._statuses.update({node_id: Status.IDLE for node_id in self._order})
        self.inner_statuses_changed.emit(None)

    # ------------------------------------------------------------------ GUI thread

    def _drain(self) -> None:
        batch = self._pump.drain()
        if batch.empty:
            return
        changed = {
            k: v
            for k, v in batch.statuses.items()
            if k in self._order and not (self._stopping and v is Status.IDLE)
        }
        self._keep_held_nodes(changed, batch)
        self._statuses.update(changed)
        inside = {k: v for k, v in batch.statuses.items() if "/" in k}  # inside instances
        if inside:
            self.inner_statuses_changed.emit(inside)
        self._messages.update({k: v for k, v in batch.messages.items() if k in self._order})
        if changed:
            self.statuses_changed.emit(changed)
            self._update_running()
        for key, value in batch.writes.items():
            self.blackboard_written.emit(key, value)
        if batch.written:
            self._emit_entries(batch)
        self._emit_logs(batch)
        if batch.failures:
            self._update_failure()
        if batch.finished is not None:
            self._finish(batch.finished)
        elif batch.paused is not None:
            self._paused(batch.paused.node_id, batch.paused.why)

    def _paused(self, node_id: str, why: str) -> None:
        """The run paused by itself: say where, on the node of the plan that shows it."""
        executor = self._executor
        if executor is None or executor.state is not ExecutorState.PAUSED:
            return  # resumed (or stepped) since: the pause is over
        self._set_state(ExecutorState.PAUSED)
        self.log_message.emit(f"Paused at {self._label(node_id)}: {why}", "info")
        self.run_paused.emit(node_id.split("/")[0], why)

    def _since_start(self, entry: BlackboardEntry) -> BlackboardEntry:
        """``entry`` with its time in seconds since the run started."""
        return dataclasses.replace(entry, time=max(0.0, entry.time - self._started_at))

    def _emit_entries(self, batch: Batch) -> None:
        """The newest write of each key in ``batch``, as entries (at most one per key per
        drain: a plan that writes at every tick costs the GUI one row update a frame).
        """
        board = self._last_board
        entries = [
            BlackboardEntry(
                e.key,
                e.value,
                board.type_of(e.key) if board is not None else None,
                e.node_id,
                e.tick,
                e.time,
            )
            for e in batch.written.values()
        ]
        self.entries_written.emit([self._since_start(e) for e in entries])

    def _keep_held_nodes(self, changed: dict[str, Status], batch: Batch) -> None:
        """A hold halts the running leaves (the engine resets them to IDLE) but the run is not
        over: they go on once the cell is clear, so they stay shown RUNNING (amber) while it
        is held. Their resets may have come with the drain before the hold's event.
        """
        holding = any(batch.holds)
        idled = {k for k in batch.idled if changed.get(k) is Status.IDLE}
        if holding or self._held:
            changed.update(dict.fromkeys(idled, RUNNING))
            if holding and not self._held:
                changed.update(
                    {k: RUNNING for k in self._idled if self._statuses.get(k) is Status.IDLE}
                )
            idled = set()
        self._idled = idled

    def _hold_text(self, reason: str) -> str:
        """What the Instructor says of a hold: why, and how the operator clears it."""
        cell = self.session.cell
        status = cell.status() if isinstance(cell, ReportsStatus) else None
        hint = status.hint if status is not None and status.problem == reason else ""
        return f"held: {reason}" + (f", {hint}" if hint else "")

    def _emit_logs(self, batch: Batch) -> None:
        for reason in batch.holds:
            if reason:
                text = self._hold_text(reason)
                self.log_message.emit(
                    f"The run is {text} (it goes on once the robot is ready)", "warning"
                )
            else:
                text = ""
                self.log_message.emit("The robot is ready again: the run goes on", "info")
            if reason != self._held:
                self._held = reason
                self.hold_changed.emit(reason, text)
        for node_id, message in batch.logs:
            self.log_message.emit(f"{self._label(node_id)}: {message}", "info")
        described: dict[str, str] = {}
        for node_id, message, error in batch.failures:
            if node_id in self._order:
                described[node_id] = failure_text(error, message)
                text = failed_words(self._label(node_id), error, message)
                if batch.statuses.get(node_id) is Status.FAILURE:  # the failure panel shows it
                    self._messages[node_id] = described[node_id]
                    self._said[node_id] = text
                self.log_message.emit(text, "error")
        if described:
            self.failures_described.emit(described)

    def _update_running(self) -> None:
        running = sorted(
            (k for k, v in self._statuses.items() if v is Status.RUNNING),
            key=lambda k: self._order[k][1],
        )
        if running != self._running:
            self._running = running
            self.running_nodes_changed.emit(list(running))

    def _deepest_failure(self) -> tuple[str, str]:
        failed = [k for k, v in self._statuses.items() if v is Status.FAILURE]
        if not failed:
            return "", ""
        node_id = max(failed, key=lambda k: self._order[k])
        return node_id, self._messages.get(node_id, "")

    def _update_failure(self) -> None:
        node_id, message = self._deepest_failure()
        if node_id:
            self._set_failure(node_id, message)

    def _set_failure(self, node_id: str, message: str, text: str = "") -> None:
        """The failure shown; ``text`` what to say ("" : as the log said it)."""
        if not text and node_id:
            text = self._said.get(node_id) or failed_words(self._label(node_id), "", message)
        if (node_id, text) != self._failure:
            self._failure = (node_id, text)
            self.failure_changed.emit(node_id, text)

    def _finish(self, event: RunFinished) -> None:
        self._timer.stop()
        self._executor = None
        if self._held:
            self._held = ""
            self.hold_changed.emit("", "")
        failures, self._failures = self._failures, None
        cause = failures.failed_run() if failures is not None else None
        others = tuple(failures.on_the_way()) if failures is not None else ()
        failed, message = ("", "")
        if event.status is Status.FAILURE and event.reason == "finished" and cause is not None:
            failed = cause.node_id.split("/")[0]  # inside an instance: the instance is shown
            message = failure_text(cause.error, cause.message)
            self._set_failure(failed, message, cause.describe())
        else:
            if event.status is Status.FAILURE:
                failed, message = self._deepest_failure()
            self._set_failure(failed, message or (event.message if failed else ""))
        tips: dict[str, str] = {}
        for root in (*others, *([cause] if cause else [])):  # the run's cause last: it wins
            if root.node_id in self._order:
                tips[root.node_id] = root.tip()
            elif root.node_id.split("/")[0] in self._order:  # inside an instance: its
                tips[root.node_id.split("/")[0]] = f"{root.node}: {root.tip()}"  # tip names it
        if tips:
            self.failures_described.emit(tips)
        if event.reason != "finished":
            halted = [k for k, v in self._statuses.items() if v is Status.RUNNING]
            if halted:
                self.nodes_halted.emit(halted)
        if self._running:
            self._running = []
            self.running_nodes_changed.emit([])
        for other in others:
            self.log_message.emit(f"On the way: {other.describe()}", "info")
        level = "info" if event.status in (Status.SUCCESS, Status.SKIPPED) else "warning"
        self.log_message.emit(self._summary(event, self._failure[1] if failed else ""), level)
        self.debugging.run_ended()
        self._set_state(ExecutorState.FINISHED)
        outcome = RunOutcome(event, failed, message, dict(self._statuses), cause, others)
        self.run_finished.emit(outcome)

    def _summary(self, event: RunFinished, why: str = "") -> str:
        """The run's last log line; a failed run says why: its root cause, the node the
        failure started at (not the composites above it, "Selector failed").
        """
        name = (self._plan.name if self._plan else "") or "the plan"
        if event.reason != "finished":
            return f"Run of {name} {event.reason} after {event.tick} ticks"
        text = f"Run of {name} ended: {event.status.value} after {event.tick} ticks"
        if event.status is Status.FAILURE and why:
            text += f": {why}"
        return text

    def _label(self, node_id: str) -> str:
        """What the log calls a node; inside an instance (runtime id "instance/inner"), the
        instance's label then the inner node's: "greet > say".
        """
        plan = self._plan
        if plan is None:
            return node_id
        first, *inner = node_id.split("/")
        node = plan.find(first)
        labels = []
        for part in inner:
            if node is None or node.subtree is None:
                return node_id
            labels.append(node.label)
            subtree = plan.subtree(node.subtree)
            node = subtree.tree.find(part) if subtree is not None else None
        if node is None:
            return node_id
        return " > ".join([*labels, node.label])

    def _set_state(self, state: ExecutorState) -> None:
        if state != self._state:
            self._state = state
            self.run_state_changed.emit(state)


def _depth_order(plan: PlanSpec) -> dict[str, tuple[int, int]]:
    """Node id -> (depth, position in tick order): the deepest, latest failure sorts last."""
    order: dict[str, tuple[int, int]] = {}
    stack = [(plan.tree, 0)] if plan.tree is not None else []
    while stack:
        node, depth = stack.pop()
        assert node is not None
        order[node.id] = (depth, len(order))
        stack.extend((child, depth + 1) for child in reversed(node.children))
    return order
