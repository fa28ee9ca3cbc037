"""Typed errors: a node's FAILURE carries an ErrorType, up the tree, in events and traces."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from bt_fakes import FuncOperation, JobOperation, ScriptedLeaf, leaf, with_children

from engine.composites import Selector, Sequence
from engine.decorators import ForceFailure, Inverter, Retry, Timeout
from engine.error_types import ErrorType, parse_error_types
from engine.events import StatusChanged
from engine.operations import Job, OperationCall, OperationFailed
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS
from engine.trace import TraceRecorder, format_timeline, read_trace


def raising(exc: Exception) -> FuncOperation:
    def start(call: OperationCall) -> Job:
        raise exc

    return FuncOperation(start)


@pytest.mark.parametrize(
    ("operation", "error"),
    [
        (FuncOperation(lambda call: Job.failed("no cup", ErrorType.NOT_FOUND)), "not_found"),
        (FuncOperation(lambda call: Job.failed()), "failed"),
        (FuncOperation(lambda call: Job.answer(False)), "failed"),
        (raising(OperationFailed("slipped", ErrorType.GRASP_FAILED)), "grasp_failed"),
        (raising(OperationFailed("plain")), "failed"),
        (raising(ZeroDivisionError("oops")), "error"),
    ],
)
def test_a_leaf_failure_carries_its_type(ctx: Any, operation: Any, error: str) -> None:
    node = leaf(ctx, operation)
    assert node.tick() is FAILURE
    assert node.error is ErrorType(error)


def test_a_job_failed_later_and_a_missing_reference(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work)
    assert node.tick() is RUNNING
    work.job.fail("stopped", ErrorType.PROTECTIVE_STOP)
    assert node.tick() is FAILURE and node.error is ErrorType.PROTECTIVE_STOP
    node.reset()
    assert node.error is None and node.status is IDLE
    missing = leaf(ctx, FuncOperation(lambda call: Job.done()), refs={"x": "NOPE"})
    assert missing.tick() is FAILURE and missing.error is ErrorType.INVALID_INPUT


def test_a_halted_job_says_halted() -> None:
    job = Job()
    job.cancel()
    assert job.error is ErrorType.HALTED and job.message == "halted"


def test_composites_and_pass_through_decorators_carry_the_childs_type(ctx: Any) -> None:
    bad = leaf(ctx, FuncOperation(lambda call: Job.failed("gone", ErrorType.OBJECT_LOST)), "a")
    seq = with_children(Sequence(ctx, "s"), [ScriptedLeaf(ctx, "ok"), bad])
    assert seq.tick() is FAILURE and seq.error is ErrorType.OBJECT_LOST
    first = leaf(ctx, FuncOperation(lambda call: Job.failed("x", ErrorType.COLLISION)), "b")
    last = leaf(ctx, FuncOperation(lambda call: Job.failed("y", ErrorType.NOT_FOUND)), "c")
    sel = with_children(Selector(ctx, "sel"), [first, last])
    assert sel.tick() is FAILURE and sel.error is ErrorType.NOT_FOUND  # the last option's
    retry = Retry(ctx, "r", count=2)
    retry.set_children([leaf(ctx, FuncOperation(lambda c: Job.failed("z", ErrorType.TIMEOUT)))])
    assert retry.tick() is RUNNING and retry.tick() is FAILURE
    assert retry.error is ErrorType.TIMEOUT


def test_decorators_that_make_a_failure_name_their_own(ctx: Any, clock: Any) -> None:
    inverter = with_children(Inverter(ctx, "i"), [ScriptedLeaf(ctx, "ok", SUCCESS)])
    assert inverter.tick() is FAILURE and inverter.error is ErrorType.FAILED
    forced = ForceFailure(ctx, "f")
    forced.set_children([leaf(ctx, raising(KeyError("k")))])
    assert forced.tick() is FAILURE and forced.error is ErrorType.FAILED
    limit = with_children(Timeout(ctx, "t", seconds=1.0), [ScriptedLeaf(ctx, "slow", RUNNING)])
    assert limit.tick() is RUNNING
    clock.advance(1.5)
    assert limit.tick() is FAILURE and limit.error is ErrorType.TIMEOUT


def test_the_type_is_in_the_event_and_the_trace_and_old_traces_read(tmp_path: Path) -> None:
    path = tmp_path / "t.trace.jsonl"
    recorder = TraceRecorder(path)
    recorder(StatusChanged(1, "n1", RUNNING, FAILURE, "no marker", 1.0, "not_found"))
    recorder(StatusChanged(2, "n2", RUNNING, FAILURE, "old style", 2.0))
    recorder.close()
    trace = read_trace(path)
    assert trace.events[0]["error"] == "not_found"
    assert "error" not in trace.events[1]  # a trace without the field reads as before
    lines = list(format_timeline(trace))
    assert lines[0].endswith("(not_found: no marker)")
    assert lines[1].endswith("(old style)")


def test_parse_error_types() -> None:
    assert parse_error_types("any") is None
    assert parse_error_types(" grasp_failed, NOT_FOUND ") == {
        ErrorType.GRASP_FAILED,
        ErrorType.NOT_FOUND,
    }
    with pytest.raises(ValueError, match="unknown error type 'dropped'"):
        parse_error_types("grasp_failed, dropped")
    with pytest.raises(ValueError, match="at least one"):
        parse_error_types(" , ")


def test_the_executor_reports_the_type_with_the_failure(registry: Any) -> None:
    from bt_fakes import Recorder, logic, op, plan

    from engine.build import build_tree
    from engine.executor import run_to_end
    from engine.spec import NodeKind

    spec = plan(logic(NodeKind.SEQUENCE, op("debug.fail", "look", error="not_found")))
    tree = build_tree(spec, registry)
    recorder = Recorder()
    run_to_end(tree, 200.0, timeout=5.0, listeners=[recorder])
    failed = [e for e in recorder.of(StatusChanged) if e.new is FAILURE]
    assert failed and {e.error for e in failed} == {"not_found"}  # the leaf and its parents
    others = [e for e in recorder.of(StatusChanged) if e.new is not FAILURE]
    assert all(e.error == "" for e in others)
