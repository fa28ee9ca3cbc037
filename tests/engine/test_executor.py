"""The executor: its thread, event-driven wake-ups, control, and listeners.

No sleep decides an outcome: the tests synchronise with threading events, ``wait_until`` on
a state, and ``executor.wait(timeout)`` (the timeouts only bound a failing test).
"""

from __future__ import annotations

import threading
from typing import Any

import pytest
from bt_fakes import (
    JobOperation,
    Recorder,
    ScriptedLeaf,
    leaf,
    logic,
    op,
    plan,
    rooted,
    wait_until,
    with_children,
)

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.composites import Parallel
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.events import BlackboardWritten, LogMessage, RunFinished, RunStarted, StatusChanged
from engine.executor import Executor, ExecutorState, run_to_end
from engine.hold import Hold
from engine.node import Node
from engine.spec import NodeKind
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status
from engine.tree import BehaviorTree


def hold_of(reason: str) -> Hold | None:
    """A protective stop in words, as a cell's hold check answers (None when clear)."""
    return Hold(reason, ErrorType.PROTECTIVE_STOP) if reason else None


NO_PERIOD = 0.01  # Hz: a period of 100 s, so that only wake-ups and steps tick


def forever_running() -> tuple[BehaviorTree, ScriptedLeaf]:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "busy", RUNNING)
    return rooted(ctx, node), node


def started(executor: Executor) -> Executor:
    executor.start()
    return executor


# ---------------------------------------------------------------------- event-driven


def test_a_job_finished_from_another_thread_ticks_at_once_not_at_the_next_period() -> None:
    ctx = TreeContext()
    work = JobOperation()
    tree = rooted(ctx, leaf(ctx, work, "move"))
    # The next periodic tick comes only after 1000 s: a run that ends at all was woken.
    executor = started(Executor(tree, rate_hz=0.001))
    assert work.started.wait(30.0)
    work.job.succeed()  # from the test thread, as a robot backend would
    result = executor.wait(60.0)
    assert result is not None and result.status is SUCCESS and result.reason == "finished"
    assert result.tick == 2  # the tick that started the job, the one its end woke


def test_the_executor_ticks_at_its_rate_when_nothing_wakes_it() -> None:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "a", RUNNING, RUNNING, SUCCESS)
    result = run_to_end(rooted(ctx, node), rate_hz=200.0, timeout=5.0)
    assert (result.status, result.tick, node.updates) == (SUCCESS, 3, 3)


class CountingWorld:
    """A lockstep that counts how far the engine let its world go, and when it was released."""

    def __init__(self, on_advance: Any = None) -> None:
        self.advanced: list[float] = []
        self.released = 0
        self.on_advance = on_advance

    def advance(self, seconds: float) -> None:
        self.advanced.append(seconds)
        if self.on_advance is not None:
            self.on_advance(len(self.advanced))

    def release(self) -> None:
        self.released += 1


def test_in_lockstep_each_tick_lets_the_world_go_one_period_and_ends_released() -> None:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "a", RUNNING, RUNNING, SUCCESS)
    world = CountingWorld()
    # At 0.001 Hz the wall clock would bring the second tick after 1000 s: the world's does.
    result = run_to_end(rooted(ctx, node), rate_hz=0.001, timeout=30.0, lockstep=world)
    assert (result.status, result.tick, node.updates) == (SUCCESS, 3, 3)
    assert world.advanced == [1000.0, 1000.0]  # after the two ticks that left it running
    assert world.released == 1


def test_in_lockstep_a_job_that_ends_while_the_world_goes_on_is_seen_at_the_next_tick() -> None:
    ctx = TreeContext()
    work = JobOperation()
    tree = rooted(ctx, leaf(ctx, work, "move"))
    # The job ends (as a motion does, on the physics thread) while the world goes its one
    # period after tick 1: tick 2 sees it, and the world went on just once.
    world = CountingWorld(on_advance=lambda n: work.job.succeed() if n == 1 else None)
    result = run_to_end(tree, rate_hz=20.0, timeout=30.0, lockstep=world)
    assert result.status is SUCCESS and result.tick == 2
    assert world.advanced == [0.05] and world.released == 1


# ---------------------------------------------------------------------- control


def test_start_paused_ticks_only_on_step() -> None:
    tree, node = forever_running()
    executor = Executor(tree, rate_hz=1000.0)
    executor.start(paused=True)
    assert executor.state is ExecutorState.PAUSED
    executor.step()
    assert wait_until(lambda: tree.ctx.tick_count == 1)
    executor.step()
    assert wait_until(lambda: tree.ctx.tick_count == 2)
    executor.stop()
    result = executor.wait(5.0)
    assert result is not None and result.reason == "stopped"
    assert tree.ctx.tick_count == 2  # at 1000 Hz, anything but the two steps would show
    assert node.updates == 2


def test_pause_step_resume() -> None:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "a", *([RUNNING] * 5), SUCCESS)
    tree = rooted(ctx, node)
    executor = started(Executor(tree, rate_hz=NO_PERIOD))
    assert wait_until(lambda: node.updates == 1)
    executor.pause()
    assert executor.state is ExecutorState.PAUSED
    executor.step()
    executor.step()
    assert wait_until(lambda: node.updates == 3)
    executor.resume()
    assert executor.state is ExecutorState.RUNNING
    executor.wake()  # with a 100 s period, only a wake-up can tick now
    assert wait_until(lambda: node.updates >= 4)
    executor.stop()
    result = executor.wait(5.0)
    assert result is not None and result.reason == "stopped"
    assert node.updates == 4
    assert node.halts == 1


def test_a_step_asked_for_while_running_is_not_kept_for_later() -> None:
    tree, node = forever_running()
    executor = started(Executor(tree, rate_hz=NO_PERIOD))
    assert wait_until(lambda: node.updates == 1)
    for _ in range(3):
        executor.step()  # running: ignored
    executor.pause()
    executor.step()
    assert wait_until(lambda: node.updates == 2)
    executor.stop()
    assert executor.wait(5.0) is not None
    assert node.updates == 2


def test_stop_halts_running_leaves_exactly_once() -> None:
    ctx = TreeContext()
    ops = [JobOperation(), JobOperation()]
    par = with_children(Parallel(ctx, "par"), [leaf(ctx, o, f"job{i}") for i, o in enumerate(ops)])
    tree = rooted(ctx, par)
    recorder = Recorder()
    executor = started(Executor(tree, rate_hz=NO_PERIOD, listeners=[recorder]))
    assert all(o.started.wait(5.0) for o in ops)
    executor.stop()
    executor.stop("again")  # the first reason stays
    result = executor.wait(5.0)
    assert result is not None
    assert (result.reason, result.status) == ("stopped", RUNNING)
    assert executor.state is ExecutorState.FINISHED
    assert [o.job.cancels for o in ops] == [1, 1]
    tree.reset()
    assert [o.job.cancels for o in ops] == [1, 1]
    assert recorder.statuses("job0") == [RUNNING, IDLE]
    assert recorder.events[-1] == result


def test_stop_while_paused_before_any_tick() -> None:
    tree, node = forever_running()
    executor = Executor(tree)
    executor.start(paused=True)
    executor.stop()
    result = executor.wait(5.0)
    assert result is not None and result.reason == "stopped" and result.tick == 0
    assert node.updates == 0


def test_an_executor_runs_once_and_needs_a_positive_rate() -> None:
    tree, _ = forever_running()
    executor = started(Executor(tree))
    with pytest.raises(RuntimeError, match="runs once"):
        executor.start()
    executor.stop()
    with pytest.raises(ValueError, match="above 0 Hz"):
        Executor(tree, rate_hz=0)


def test_run_to_end_stops_with_timeout() -> None:
    tree, node = forever_running()
    result = run_to_end(tree, rate_hz=1000.0, timeout=0.05)
    assert (result.reason, result.status) == ("timeout", RUNNING)
    assert node.halts == 1


def test_a_bug_in_a_node_ends_the_run_with_error_and_halts_the_rest() -> None:
    class Broken(Node):
        def update(self) -> Status:
            raise AssertionError("engine bug")

    ctx = TreeContext()
    busy = ScriptedLeaf(ctx, "busy", RUNNING)
    tree = rooted(ctx, with_children(Parallel(ctx, "par"), [busy, Broken(ctx, "broken")]))
    result = run_to_end(tree, timeout=5.0)
    assert (result.reason, result.message) == ("error", "AssertionError: engine bug")
    assert busy.halts == 1


# ---------------------------------------------------------------------- listeners


def test_listeners_get_status_changes_writes_logs_and_the_end(registry: CapabilityRegistry) -> None:
    spec = plan(
        logic(
            NodeKind.SEQUENCE,
            op("debug.set_param", "remember", value=5, name="$COUNT"),
            op("debug.log", "say", message="hello"),
            op("debug.running", "work", ticks=1),
        ),
        name="demo",
    )
    tree = build_tree(spec, registry)
    recorder = Recorder()
    executor = Executor(tree, rate_hz=1000.0, plan_name="demo")
    executor.add_listener(recorder)
    executor.start()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
    events = recorder.events
    assert isinstance(events[0], RunStarted) and events[0].plan == "demo"
    assert events[-1] == result and isinstance(result, RunFinished)
    set_id, log_id, work_id = (n.id for n in (spec.tree.children if spec.tree else []))
    assert recorder.statuses(set_id) == [SUCCESS]
    assert recorder.statuses(work_id) == [RUNNING, SUCCESS]
    assert recorder.statuses("root") == [RUNNING, SUCCESS]  # the root finishes on tick 2
    (write,) = recorder.of(BlackboardWritten)
    assert (write.key, write.value, write.node_id, write.tick) == ("COUNT", 5, set_id, 1)
    assert [(e.node_id, e.message) for e in recorder.of(LogMessage)] == [(log_id, "hello")]
    ticks = [e.tick for e in recorder.of(StatusChanged)]
    assert ticks == sorted(ticks)


def test_a_listener_that_raises_stops_neither_the_run_nor_the_others() -> None:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "a", RUNNING, FAILURE)

    def broken(event: Any) -> None:
        raise ValueError("listener bug")

    recorder = Recorder()
    executor = started(Executor(rooted(ctx, node), rate_hz=1000.0, listeners=[broken, recorder]))
    result = executor.wait(5.0)
    assert result is not None and (result.status, result.reason) == (FAILURE, "finished")
    assert recorder.statuses("a") == [RUNNING, FAILURE]
    assert recorder.events[-1] == result


def test_a_slow_listener_does_not_hold_up_the_run() -> None:
    ctx = TreeContext()
    node = ScriptedLeaf(ctx, "a", *([RUNNING] * 20), SUCCESS)
    release = threading.Event()
    blocked = threading.Event()

    def slow(event: Any) -> None:
        blocked.set()
        release.wait(10.0)  # holds the dispatcher until the test lets go

    recorder = Recorder()
    executor = started(Executor(rooted(ctx, node), rate_hz=1000.0, listeners=[slow, recorder]))
    try:
        assert blocked.wait(5.0)
        assert wait_until(lambda: executor.state is ExecutorState.FINISHED)
        assert executor.result is not None and executor.result.status is SUCCESS
        assert recorder.events == []  # nothing delivered yet: the ticks did not wait for it
    finally:
        release.set()
    assert executor.wait(5.0) == executor.result
    assert recorder.events[-1] == executor.result
    assert recorder.statuses("a") == [RUNNING, SUCCESS]


# ---------------------------------------------------------------------- hold (a cell stops)


def test_a_hold_halts_the_running_leaf_within_a_tick_and_the_run_goes_on_after() -> None:
    from engine.composites import Sequence
    from engine.events import RunHeld

    ctx = TreeContext()
    first, second = JobOperation(), JobOperation()
    seq = with_children(
        Sequence(ctx, "seq"), [leaf(ctx, first, "first"), leaf(ctx, second, "second")]
    )
    tree = rooted(ctx, seq)
    reason = [""]
    recorder = Recorder()
    executor = started(
        Executor(tree, rate_hz=200.0, listeners=[recorder], hold=lambda: hold_of(reason[0]))
    )
    assert first.started.wait(5.0)
    first.jobs[0].succeed()
    assert second.started.wait(5.0)
    tick = tree.ctx.tick_count
    reason[0] = "protective stop"
    assert wait_until(lambda: executor.held == "protective stop")
    assert tree.ctx.tick_count <= tick + 1  # held before the next tick evaluated anything
    assert second.jobs[0].cancels == 1  # the running leaf was halted
    assert tree.nodes["seq"].status is RUNNING  # the sequence keeps its place
    reason[0] = ""
    assert wait_until(lambda: len(second.jobs) == 2)  # the halted leaf starts afresh
    assert len(first.jobs) == 1  # the finished one is not run again
    second.jobs[1].succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
    assert [e.reason for e in recorder.of(RunHeld)] == ["protective stop", ""]


def test_a_hold_check_that_raises_holds_the_run_with_its_message() -> None:
    tree, node = forever_running()

    def broken() -> Hold | None:
        raise RuntimeError("no state")

    executor = started(Executor(tree, rate_hz=200.0, hold=broken))
    assert wait_until(lambda: "no state" in executor.held)
    assert node.updates == 0
    executor.stop()
    assert executor.wait(5.0) is not None
