"""The debugger: breakpoints, stepping, skipped nodes and forced results in a running executor.

The tests synchronise on RunPaused events and the executor's state, never on sleeps.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import Recorder, ScriptedLeaf, rooted, wait_until, with_children

from engine.catch import Catch
from engine.composites import Sequence
from engine.context import TreeContext
from engine.debugger import AFTER, BEFORE, Breakpoint, Debugger, Forced
from engine.error_types import ErrorType
from engine.events import RunPaused, StatusChanged
from engine.executor import Executor, ExecutorState
from engine.script import ScriptSyntaxError
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS
from engine.tree import BehaviorTree
from engine.types import ParamType

RATE = 1000.0


def three_steps() -> tuple[BehaviorTree, dict[str, ScriptedLeaf]]:
    """top: a, inner (b, c), d; b runs one tick before it succeeds."""
    ctx = TreeContext()
    leaves = {
        "a": ScriptedLeaf(ctx, "a"),
        "b": ScriptedLeaf(ctx, "b", RUNNING, SUCCESS),
        "c": ScriptedLeaf(ctx, "c"),
        "d": ScriptedLeaf(ctx, "d"),
    }
    inner = with_children(Sequence(ctx, "inner", "inner"), [leaves["b"], leaves["c"]])
    top = with_children(Sequence(ctx, "top", "top"), [leaves["a"], inner, leaves["d"]])
    return rooted(ctx, top), leaves


def paused(recorder: Recorder, count: int = 1) -> RunPaused:
    assert wait_until(lambda: len(recorder.of(RunPaused)) >= count), "the run did not pause"
    event: RunPaused = recorder.of(RunPaused)[count - 1]
    return event


def start(tree: BehaviorTree, debugger: Debugger, paused: bool = False) -> tuple[Executor, Any]:
    recorder = Recorder()
    executor = Executor(tree, RATE, [recorder], debugger=debugger)
    executor.start(paused=paused)
    return executor, recorder


def test_a_breakpoint_before_a_node_pauses_before_its_tick_and_the_run_goes_on() -> None:
    tree, leaves = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("c"))
    executor, recorder = start(tree, debugger)
    hit = paused(recorder)
    assert (hit.node_id, hit.where) == ("c", BEFORE) and "breakpoint before c" in hit.why
    assert executor.state is ExecutorState.PAUSED
    assert leaves["b"].status is SUCCESS and leaves["c"].updates == 0
    executor.resume()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
    assert len(recorder.of(RunPaused)) == 1


def test_a_breakpoint_after_a_node_pauses_before_its_parent_sees_the_result() -> None:
    tree, leaves = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("b", before=False, after=True))
    executor, recorder = start(tree, debugger)
    hit = paused(recorder)
    assert (hit.node_id, hit.where) == ("b", AFTER) and "b is SUCCESS" in hit.why
    assert tree.nodes["inner"].status is RUNNING and leaves["c"].updates == 0
    executor.resume()
    assert executor.wait(5.0) is not None and tree.status is SUCCESS


def test_a_condition_on_the_blackboard_decides_whether_it_stops() -> None:
    tree, _ = three_steps()
    tree.blackboard.declare("count", ParamType.NUMBER)
    tree.blackboard.set("count", 1)
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("a", condition="count > 2"))
    debugger.set_breakpoint(Breakpoint("d", condition="count < 2"))
    executor, recorder = start(tree, debugger)
    hit = paused(recorder)
    assert hit.node_id == "d" and "(count < 2 is true)" in hit.why
    executor.resume()
    assert executor.wait(5.0) is not None
    with pytest.raises(ScriptSyntaxError):
        Breakpoint("a", condition="count >")


def test_step_next_pauses_at_the_next_status_change() -> None:
    tree, _ = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("b"))
    executor, recorder = start(tree, debugger)
    paused(recorder)
    executor.step_next()
    hit = paused(recorder, 2)
    assert (hit.node_id, hit.where) == ("b", AFTER) and "b is RUNNING" in hit.why
    executor.step_next()
    assert paused(recorder, 3).node_id == "inner"  # a parent turns RUNNING after its child
    executor.step_next()
    assert paused(recorder, 4).node_id == "top"
    executor.step_next()
    assert paused(recorder, 5).node_id == "root"
    executor.step_next()
    assert paused(recorder, 6).why == "step: b is SUCCESS"
    executor.resume()
    assert executor.wait(5.0) is not None and tree.status is SUCCESS


def test_step_over_runs_the_subtree_to_its_end() -> None:
    tree, _ = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("inner"))
    executor, recorder = start(tree, debugger)
    paused(recorder)
    executor.step_over()
    hit = paused(recorder, 2)
    assert hit.node_id == "inner" and hit.why == "step: inner is SUCCESS"
    assert tree.nodes["c"].status is SUCCESS and tree.nodes["d"].status is IDLE
    executor.step_over()  # inner has finished: the next change outside it
    assert paused(recorder, 3).node_id == "d"
    executor.resume()
    assert executor.wait(5.0) is not None


def test_run_to_a_node_from_a_paused_start() -> None:
    tree, leaves = three_steps()
    executor, recorder = start(tree, Debugger(), paused=True)
    executor.run_to("d")
    hit = paused(recorder)
    assert (hit.node_id, hit.where, hit.why) == ("d", BEFORE, "ran to d")
    assert leaves["c"].status is SUCCESS and leaves["d"].updates == 0
    executor.resume()
    assert executor.wait(5.0) is not None
    assert not any("tick" in vars(node) for node in tree.iterate())  # the run-to is spent


def test_stopped_while_paused_inside_a_tick_halts_and_ends() -> None:
    tree, leaves = three_steps()
    leaves["b"].set_script(RUNNING)
    executor, recorder = start(tree, Debugger(), paused=True)
    executor.run_to("b")
    paused(recorder)
    executor.step_next()  # b RUNNING
    paused(recorder, 2)
    executor.stop()
    result = executor.wait(5.0)
    assert result is not None and result.reason == "stopped"
    assert leaves["b"].halts == 1 and all(node.status is IDLE for node in tree.iterate())


def test_a_skipped_node_reports_skipped_and_is_not_run() -> None:
    tree, leaves = three_steps()
    debugger = Debugger()
    debugger.skip("b")
    executor, recorder = start(tree, debugger)
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
    assert leaves["b"].updates == 0 and recorder.statuses("b")[0] is SKIPPED
    assert leaves["c"].updates == 1
    assert "skipped by the operator" in next(
        e.message for e in recorder.of(StatusChanged) if e.node_id == "b"
    )


def test_a_forced_failure_runs_the_handler_of_a_catch_that_takes_its_type() -> None:
    ctx = TreeContext()
    grasp, recover = ScriptedLeaf(ctx, "grasp"), ScriptedLeaf(ctx, "recover")
    catch = with_children(Catch(ctx, "catch", "catch", {ErrorType.GRASP_FAILED}), [grasp, recover])
    tree = rooted(ctx, catch)
    debugger = Debugger()
    debugger.force("grasp", Forced(FAILURE, ErrorType.GRASP_FAILED))
    executor, recorder = start(tree, debugger)
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS  # the handler recovered
    assert grasp.updates == 0 and recover.updates == 1
    failed = [e for e in recorder.of(StatusChanged) if e.node_id == "grasp" and e.new is FAILURE]
    assert failed[0].error == "grasp_failed" and "forced to fail" in failed[0].message
    assert debugger.forced == {}  # given once: the next run runs the grasp


def test_a_result_forced_while_paused_before_a_node_is_given_when_the_run_goes_on() -> None:
    tree, leaves = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("c"))
    executor, recorder = start(tree, debugger)
    assert paused(recorder).node_id == "c"
    debugger.force("c", Forced(FAILURE))
    executor.resume()
    result = executor.wait(5.0)
    assert result is not None and result.status is FAILURE
    assert leaves["c"].updates == 0 and leaves["d"].updates == 0


def test_no_breakpoint_leaves_every_node_its_class_tick() -> None:
    tree, _ = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("c"))
    debugger.skip("a")
    Executor(tree, RATE, debugger=debugger)._attach()
    assert {n.id for n in tree.iterate() if "tick" in vars(n)} == {"a", "c"}
    debugger.clear_breakpoint("c")
    debugger.skip("a", False)
    assert not any("tick" in vars(node) for node in tree.iterate())
    with pytest.raises(ValueError):
        Forced(SKIPPED)


def test_a_pause_is_in_the_run_record(tmp_path: Any) -> None:
    from engine.trace import TraceRecorder, format_timeline, read_trace

    tree, _ = three_steps()
    debugger = Debugger()
    debugger.set_breakpoint(Breakpoint("c"))
    recorder, events = TraceRecorder(tmp_path / "run.jsonl"), Recorder()
    executor = Executor(tree, RATE, [recorder, events], debugger=debugger)
    executor.start()
    paused(events)
    executor.resume()
    assert executor.wait(5.0) is not None
    recorder.close()
    lines = list(format_timeline(read_trace(tmp_path / "run.jsonl")))
    assert any("run paused: breakpoint before c" in line for line in lines)
