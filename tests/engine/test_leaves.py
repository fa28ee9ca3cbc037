"""Operation leaves (Action, Query, Condition) with Jobs, Wait, and the blackboard."""

from __future__ import annotations

import threading
from typing import Any

import pytest
from bt_fakes import (
    CountingJob,
    FakeClock,
    FuncOperation,
    JobOperation,
    ScriptedLeaf,
    leaf,
    recording_ctx,
    with_children,
)

from engine.blackboard import Blackboard, BlackboardError
from engine.composites import Parallel, Selector, Sequence
from engine.errors import EngineError
from engine.leaves import OperationLeaf, Wait
from engine.operations import (
    InPort,
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    OperationNotFound,
    PortSpec,
    number,
)
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status
from engine.types import ParamType, Pose

QUERY = OperationKind.QUERY
CONDITION = OperationKind.CONDITION


def returns(value: Any) -> FuncOperation:
    return FuncOperation(lambda call: value)


def raises(exc: Exception) -> FuncOperation:
    def start(call: OperationCall) -> Any:
        raise exc

    return FuncOperation(start)


# ---------------------------------------------------------------------- immediate results


@pytest.mark.parametrize("value", [Job.done(), Job.answer(True), Job.done("moved")])
def test_an_immediate_success(ctx: Any, value: Any) -> None:
    assert leaf(ctx, returns(value)).tick() is SUCCESS


@pytest.mark.parametrize("value", [True, None, SUCCESS, False])
def test_start_returns_a_job_and_nothing_else(ctx: Any, value: Any) -> None:
    node = leaf(ctx, returns(value))
    assert node.tick() is FAILURE
    assert "expected a Job" in node.message


def test_a_finished_job_with_outputs_writes_them(ctx: Any) -> None:
    node = leaf(ctx, returns(Job.done("", {"pose": Pose()})), "q", QUERY, outputs={"pose": "P"})
    assert node.tick() is SUCCESS
    assert ctx.blackboard.get("P") == Pose()


@pytest.mark.parametrize(
    ("value", "kind", "message"),
    [
        (Job.failed(), OperationKind.ACTION, "failed"),
        (Job.answer(False), CONDITION, "false"),
        (Job.failed("no cup"), CONDITION, "no cup"),
    ],
)
def test_an_immediate_failure(ctx: Any, value: Any, kind: OperationKind, message: str) -> None:
    node = leaf(ctx, returns(value), kind=kind)
    assert node.tick() is FAILURE
    assert node.message == message
    assert node.is_condition is (kind is CONDITION)


def test_a_start_that_returns_nonsense_fails_the_node(ctx: Any) -> None:
    node = leaf(ctx, returns(42))
    assert node.tick() is FAILURE
    assert node.message.startswith("TypeError: start() returned 42")


# ---------------------------------------------------------------------- Jobs


def test_an_action_runs_until_its_job_finishes(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work, "move")
    assert [node.tick(), node.tick()] == [RUNNING, RUNNING]
    assert len(work.jobs) == 1  # started once, then polled
    work.job.succeed("arrived")
    assert node.tick() is SUCCESS
    assert node.message == "arrived"


def test_a_failed_job_fails_the_node_with_its_message(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work)
    node.tick()
    work.job.fail("joint limit")
    assert node.tick() is FAILURE
    assert node.message == "joint limit"


def test_the_first_finish_of_a_job_wins() -> None:
    job = Job()
    job.fail("first")
    job.succeed("second")
    assert (job.poll(), job.message, job.finished) == (FAILURE, "first", True)


def test_a_job_finished_from_another_thread_wakes_the_tree(ctx: Any) -> None:
    woken = threading.Event()
    ctx.wake = woken.set
    work = JobOperation()
    node = leaf(ctx, work)
    assert node.tick() is RUNNING
    thread = threading.Thread(target=work.job.succeed)
    thread.start()
    thread.join(5.0)
    assert woken.is_set()
    assert node.tick() is SUCCESS


def test_a_job_finished_inside_start_is_taken_in_the_same_tick(ctx: Any) -> None:
    wakes: list[int] = []
    ctx.wake = lambda: wakes.append(1)

    def start(call: OperationCall) -> Job:
        job = Job()
        job.succeed()  # finished inside start: no wake needed, the leaf polls it at once
        return job

    assert leaf(ctx, FuncOperation(start)).tick() is SUCCESS
    assert wakes == []


def test_a_job_finished_before_bind_wake_wakes_at_once() -> None:
    wakes: list[int] = []
    job = Job()
    job.succeed()
    job.bind_wake(lambda: wakes.append(1))
    assert wakes == [1]


def test_job_outputs_are_written_by_the_engine_when_polled(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work, "detect", QUERY, outputs={"pose": "CUP_POSE"})
    node.tick()
    work.job.succeed(outputs={"pose": Pose((0.5, 0.0, 0.1))})
    assert "CUP_POSE" not in ctx.blackboard  # not from the worker thread
    assert node.tick() is SUCCESS
    assert ctx.blackboard.get("CUP_POSE") == Pose((0.5, 0.0, 0.1))


def test_an_exception_in_poll_fails_the_node_and_the_tick_goes_on(ctx: Any) -> None:
    class Broken(Job):
        def poll(self) -> Status:
            raise ZeroDivisionError("division by zero")

    broken = leaf(ctx, FuncOperation(lambda call: Broken()), "broken")
    fallback = ScriptedLeaf(ctx, "fallback", SUCCESS)
    sel = with_children(Selector(ctx, "sel"), [broken, fallback])
    assert sel.tick() is SUCCESS
    assert broken.status is FAILURE
    assert broken.message == "ZeroDivisionError: division by zero"


@pytest.mark.parametrize(
    ("exc", "message"),
    [
        (RuntimeError("gripper offline"), "RuntimeError: gripper offline"),
        (OperationFailed("no cup"), "no cup"),
    ],
)
def test_an_exception_in_start_fails_the_node_and_the_tick_goes_on(
    ctx: Any, exc: Exception, message: str
) -> None:
    bad = leaf(ctx, raises(exc), "bad")
    after = ScriptedLeaf(ctx, "after", SUCCESS)
    sel = with_children(Selector(ctx, "sel"), [bad, after])
    assert sel.tick() is SUCCESS
    assert (bad.status, bad.message) == (FAILURE, message)
    assert after.updates == 1


# ---------------------------------------------------------------------- halting


def test_halting_cancels_the_job_once_and_is_idempotent(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work)
    node.tick()
    node.reset()
    node.reset()
    node.halt()
    assert work.job.cancels == 1
    assert work.job.poll() is FAILURE and work.job.message == "halted"
    assert node.tick() is RUNNING and len(work.jobs) == 2  # a fresh start after the reset


def test_job_cancel_is_idempotent_by_itself() -> None:
    job = CountingJob()
    job.cancel()
    job.cancel()
    assert job.cancels == 1


def test_a_finished_leaf_is_not_cancelled_on_reset(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work)
    node.tick()
    work.job.succeed()
    node.tick()
    node.reset()
    assert work.job.cancels == 0


def test_a_cancel_that_raises_does_not_break_the_reset(ctx: Any) -> None:
    def explode() -> None:
        raise OSError("robot unreachable")

    bad = leaf(ctx, FuncOperation(lambda call: Job(on_cancel=explode)), "bad")
    good_work = JobOperation()
    good = leaf(ctx, good_work, "good")
    par = with_children(Parallel(ctx, "par"), [bad, good])
    assert par.tick() is RUNNING
    par.reset()
    assert (bad.status, good.status, par.status) == (IDLE, IDLE, IDLE)
    assert good_work.job.cancels == 1
    assert ctx.logs == [("bad", "error while halting: OSError: robot unreachable")]


# ---------------------------------------------------------------------- queries and references


def test_a_query_succeeds_only_when_it_wrote_its_output(ctx: Any) -> None:
    def start(call: OperationCall) -> Job:
        call.write("pose", Pose())
        return Job.done()

    node = leaf(ctx, FuncOperation(start), "where", QUERY, outputs={"pose": "CUP_POSE"})
    assert node.tick() is SUCCESS
    assert ctx.blackboard.get("CUP_POSE") == Pose()


def test_a_query_that_writes_nothing_fails(ctx: Any) -> None:
    node = leaf(ctx, returns(Job.done()), "where", QUERY, outputs={"pose": "CUP_POSE"})
    assert node.tick() is FAILURE
    assert node.message == "the query wrote no value for CUP_POSE"
    assert "CUP_POSE" not in ctx.blackboard


def test_a_query_must_write_again_on_each_run(ctx: Any) -> None:
    runs = iter([True, False])

    def start(call: OperationCall) -> Job:
        if next(runs):
            call.write("pose", Pose())
        return Job.done()

    node = leaf(ctx, FuncOperation(start), "where", QUERY, outputs={"pose": "CUP_POSE"})
    assert node.tick() is SUCCESS
    node.reset()
    assert node.tick() is FAILURE  # the value of the first run does not count


def test_an_output_the_plan_does_not_store_is_dropped(ctx: Any) -> None:
    def start(call: OperationCall) -> Job:
        call.write("extra", 1.0)
        return Job.done()

    assert leaf(ctx, FuncOperation(start), "act").tick() is SUCCESS
    assert len(ctx.blackboard) == 0


def test_references_are_read_at_each_start(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work, "move", fixed={"speed": 0.2}, refs={"target": "CUP_POSE"})
    ctx.blackboard.set("CUP_POSE", "first")
    node.tick()
    ctx.blackboard.set("CUP_POSE", "second")
    node.reset()
    node.tick()
    assert work.calls == [{"speed": 0.2, "target": "first"}, {"speed": 0.2, "target": "second"}]


def test_a_missing_reference_fails_the_node_naming_the_parameter(ctx: Any) -> None:
    work = JobOperation()
    node = leaf(ctx, work, "move", refs={"target": "CUP_POSE"})
    assert node.tick() is FAILURE
    assert node.message == "parameter 'CUP_POSE' (for 'target') has no value yet"
    assert work.jobs == []


def test_operations_log_through_the_tree(ctx: Any) -> None:
    def start(call: OperationCall) -> Job:
        call.log("closing gripper")
        return Job.done()

    leaf(ctx, FuncOperation(start), "grip").tick()
    assert ctx.logs == [("grip", "closing gripper")]


# ---------------------------------------------------------------------- blackboard


def test_typed_writes_of_another_type_are_refused() -> None:
    board = Blackboard({"CUP_POSE": ParamType.POSE})
    with pytest.raises(BlackboardError, match="parameter 'CUP_POSE' holds Pose, not str 'left'"):
        board.set("CUP_POSE", "left")
    board.declare("COUNT", ParamType.NUMBER)
    with pytest.raises(BlackboardError, match="holds Number, not bool True"):
        board.set("COUNT", True)
    board.set("COUNT", 3)
    assert board.type_of("COUNT") is ParamType.NUMBER and board.get("COUNT") == 3


def test_a_refused_write_fails_the_writing_node_with_the_reason(clock: FakeClock) -> None:
    ctx = recording_ctx(clock, Blackboard({"CUP_POSE": ParamType.POSE}))
    work = JobOperation()
    node = leaf(ctx, work, "where", QUERY, outputs={"pose": "CUP_POSE"})
    node.tick()
    work.job.succeed(outputs={"pose": 12})
    assert node.tick() is FAILURE
    assert "parameter 'CUP_POSE' holds Pose, not int 12" in node.message


def test_blackboard_reads_snapshot_and_listeners() -> None:
    board = Blackboard()
    seen: list[tuple[str, Any, str]] = []
    board.add_write_listener(lambda key, value, writer: seen.append((key, value, writer)))
    board.set("A", 1, "n1")
    with pytest.raises(BlackboardError, match="'B' has no value yet"):
        board.get("B")
    assert board.get("B", None) is None
    snap = board.snapshot()
    board.set("A", 2)
    assert snap == {"A": 1} and list(board) == ["A"] and "A" in board
    board.unset("A")
    assert len(board) == 0
    assert seen == [("A", 1, "n1"), ("A", 2, "")]


# ---------------------------------------------------------------------- Wait


def test_wait_runs_for_its_duration_on_the_tree_clock(ctx: Any, clock: FakeClock) -> None:
    node = Wait(ctx, "w", seconds=2.0)
    assert node.tick() is RUNNING
    clock.advance(1.999)
    assert node.tick() is RUNNING
    clock.advance(0.001)
    assert node.tick() is SUCCESS


def test_wait_starts_again_after_reset(ctx: Any, clock: FakeClock) -> None:
    node = Wait(ctx, "w", seconds=1.0)
    node.tick()
    clock.advance(0.5)
    node.reset()
    clock.advance(0.5)
    assert node.tick() is RUNNING


def test_wait_zero_succeeds_at_once_and_negative_is_refused(ctx: Any) -> None:
    assert Wait(ctx, "w", seconds=0).tick() is SUCCESS
    with pytest.raises(ValueError, match="at least 0 s"):
        Wait(ctx, "w", seconds=-1)


def test_a_leaf_in_a_sequence_with_a_job(ctx: Any) -> None:
    work = JobOperation()
    seq = with_children(
        Sequence(ctx, "seq"), [leaf(ctx, work, "a"), ScriptedLeaf(ctx, "b", SUCCESS)]
    )
    assert seq.tick() is RUNNING
    work.job.succeed()
    assert seq.tick() is SUCCESS


# ---------------------------------------------------------------------- typed inputs

_TARGET = PortSpec("target", (ParamType.POSE, ParamType.WAYPOINT))
_SPEED = number("speed", 0.25, unit="m/s")


def _typed_leaf(ctx: Any, work: Any) -> Any:
    return OperationLeaf(ctx, "move", "move", OperationKind.ACTION, work,
                         {"speed": 1}, {"target": "CUP_POSE"}, ports=(_TARGET, _SPEED))  # fmt: skip


def test_inputs_are_read_typed_and_in_si(ctx: Any) -> None:
    seen: list[Any] = []

    def start(call: OperationCall) -> Job:
        seen.extend([call.input(_SPEED), call.input(InPort[Any]("target", _TARGET.types))])
        return Job.done()

    ctx.blackboard.set("CUP_POSE", Pose((0.1, 0.2, 0.3)))
    assert _typed_leaf(ctx, FuncOperation(start)).tick() is SUCCESS
    assert seen == [1.0, Pose((0.1, 0.2, 0.3))]
    assert type(seen[0]) is float


def test_a_reference_of_the_wrong_type_fails_naming_port_name_and_types(ctx: Any) -> None:
    work = JobOperation()
    ctx.blackboard.set("CUP_POSE", "hello")
    node = _typed_leaf(ctx, work)
    assert node.tick() is FAILURE
    assert node.message == (
        "input 'target' reads 'CUP_POSE', which holds Text 'hello'; expected Pose or Waypoint"
    )
    assert work.jobs == []


def test_asking_for_an_input_the_manifest_lacks_fails_the_node(ctx: Any) -> None:
    node = leaf(ctx, FuncOperation(lambda call: call.input(number("nope"))), "act")
    assert node.tick() is FAILURE
    assert node.message == "'act' has no input 'nope'"


def test_operation_errors_derive_from_the_engine_root() -> None:
    assert issubclass(OperationFailed, EngineError)
    assert issubclass(OperationNotFound, EngineError)
