"""A cell's stop thrown into the plan (Intera) when a Catch takes it, else held (PolyScope).

No sleep decides an outcome: the tests finish jobs from the test thread and wait on states.
"""

from __future__ import annotations

from bt_fakes import JobOperation, Recorder, leaf, rooted, wait_until, with_children

from engine.catch import Catch
from engine.composites import Parallel, Sequence
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.events import LogMessage, RunHeld
from engine.executor import Executor
from engine.hold import Hold, catchers, stopped_leaves
from engine.leaves import OperationLeaf
from engine.operations import OperationKind
from engine.status import FAILURE, RUNNING, SUCCESS

STOP = Hold("protective stop", ErrorType.PROTECTIVE_STOP)


def caught_move(
    ctx: TreeContext, errors: set[ErrorType] | None = None
) -> tuple[Catch, JobOperation, JobOperation]:
    move, handler = JobOperation(), JobOperation()
    catch = Catch(ctx, "catch", "catch", errors, "WHY")
    with_children(catch, [leaf(ctx, move, "move"), leaf(ctx, handler, "clear")])
    return catch, move, handler


def test_a_stop_a_catch_takes_is_thrown_into_its_body_and_the_handler_runs() -> None:
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx, {ErrorType.PROTECTIVE_STOP})
    tree = rooted(ctx, catch)
    hold: list[Hold | None] = [None]
    recorder = Recorder()
    executor = Executor(tree, rate_hz=200.0, listeners=[recorder], hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0)
    hold[0] = STOP
    assert handler.started.wait(5.0)  # the handler runs while the stop lasts: no hold
    assert executor.held == ""
    node = tree.nodes["move"]
    assert (node.status, node.error, node.message) == (
        FAILURE, ErrorType.PROTECTIVE_STOP, "protective stop",
    )  # fmt: skip
    assert move.jobs[0].cancels == 1  # its work was halted
    assert tree.blackboard.get("WHY") == "protective_stop: protective stop"
    hold[0] = None  # the handler cleared it
    handler.job.succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
    assert not recorder.of(RunHeld)
    thrown = [e.message for e in recorder.of(LogMessage) if e.node_id == "move"]
    assert thrown == ["the cell threw protective_stop into the plan: protective stop"]


def test_a_stop_no_catch_takes_holds_the_run_and_clearing_resumes_it() -> None:
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx, {ErrorType.GRASP_FAILED})
    tree = rooted(ctx, catch)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0)
    hold[0] = STOP
    assert wait_until(lambda: executor.held == "protective stop")
    assert tree.nodes["move"].status is not FAILURE and not handler.jobs
    hold[0] = None
    assert wait_until(lambda: len(move.jobs) == 2)  # the move starts afresh
    move.job.succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS and not handler.jobs


def test_a_stop_is_held_when_one_running_leaf_has_no_catch() -> None:
    ctx = TreeContext()
    catch, move, _handler = caught_move(ctx)
    other = JobOperation()
    both = with_children(Parallel(ctx, "both"), [catch, leaf(ctx, other, "watch")])
    leaves = [tree_leaf for tree_leaf in both.iterate() if not tree_leaf.children]
    assert catchers(leaves[:1], ErrorType.PROTECTIVE_STOP) == [catch]
    assert catchers(leaves, ErrorType.PROTECTIVE_STOP) is None  # "watch" has none
    tree = rooted(ctx, both)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0) and other.started.wait(5.0)
    hold[0] = STOP
    assert wait_until(lambda: executor.held == "protective stop")
    executor.stop()
    assert executor.wait(5.0) is not None


def test_a_stop_spares_the_leaves_of_the_capabilities_that_only_look() -> None:
    """A camera's watch beside a caught move (a Parallel): the stop is thrown into the move
    only; the watch has no Catch of its own and goes on, and finishes the run.
    """
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx, {ErrorType.PROTECTIVE_STOP})
    watch = JobOperation()
    seeing = OperationLeaf(ctx, "watch", "watch", OperationKind.ACTION, watch,
                           capability="occupancy")  # fmt: skip
    both = with_children(Parallel(ctx, "both"), [catch, seeing])
    tree = rooted(ctx, both)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0) and watch.started.wait(5.0)
    hold[0] = Hold("protective stop", ErrorType.PROTECTIVE_STOP, frozenset({"occupancy"}))
    assert handler.started.wait(5.0)
    assert executor.held == "" and tree.nodes["watch"].status is RUNNING
    assert stopped_leaves([tree.nodes["move"], seeing], hold[0]) == [tree.nodes["move"]]
    assert watch.jobs[0].cancels == 0  # its work goes on
    hold[0] = None
    handler.job.succeed()
    watch.job.succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS


def test_a_new_stop_while_the_handler_runs_holds_the_run() -> None:
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx, {ErrorType.PROTECTIVE_STOP})
    tree = rooted(ctx, with_children(Sequence(ctx, "seq"), [catch]))
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0)
    hold[0] = STOP
    assert handler.started.wait(5.0)
    hold[0] = Hold("emergency stop", ErrorType.EMERGENCY_STOP)  # not the handler's to clear
    assert wait_until(lambda: executor.held == "emergency stop")
    assert handler.jobs[0].cancels == 1 and tree.nodes["clear"].status is not FAILURE
    executor.stop()
    assert executor.wait(5.0) is not None


def test_a_stop_of_no_known_type_is_held_even_under_a_catch_of_any_type() -> None:
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx)  # takes every type
    tree = rooted(ctx, catch)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0)
    hold[0] = Hold("the arm is powered off")  # error: failed
    assert wait_until(lambda: executor.held == "the arm is powered off")
    assert tree.nodes["move"].status is not RUNNING and not handler.jobs
    executor.stop()
    assert executor.wait(5.0) is not None


def test_a_node_that_failed_with_the_stop_first_is_not_held_while_its_handler_runs() -> None:
    ctx = TreeContext()
    catch, move, handler = caught_move(ctx, {ErrorType.PROTECTIVE_STOP})
    tree = rooted(ctx, catch)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert move.started.wait(5.0)
    # The move's own failure reaches the plan before the hold check sees the stop.
    move.job.fail("move_linear: protective stop (the wrist pressed on the table)",
                  ErrorType.PROTECTIVE_STOP)  # fmt: skip
    assert handler.started.wait(5.0)
    hold[0] = STOP
    tick = tree.ctx.tick_count
    assert wait_until(lambda: tree.ctx.tick_count > tick + 3)
    assert executor.held == "" and handler.jobs[0].cancels == 0
    hold[0] = None
    handler.job.succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS


def test_a_stop_while_the_plan_only_watches_is_thrown_into_the_watch() -> None:
    """Nothing but a camera's watch runs when the robot is hit where it stands (a machine's
    arm came down on it): the Catch around the watch gets the stop and its handler moves the
    robot away, instead of a run held with the robot in the way.
    """
    ctx = TreeContext()
    watch, handler = JobOperation(), JobOperation()
    seeing = OperationLeaf(ctx, "watch", "watch", OperationKind.ACTION, watch,
                           capability="occupancy")  # fmt: skip
    catch = Catch(ctx, "catch", "catch", {ErrorType.PROTECTIVE_STOP}, "WHY")
    with_children(catch, [seeing, leaf(ctx, handler, "back off")])
    tree = rooted(ctx, catch)
    hold: list[Hold | None] = [None]
    executor = Executor(tree, rate_hz=200.0, hold=lambda: hold[0])
    executor.start()
    assert watch.started.wait(5.0)
    stop = Hold("protective stop", ErrorType.PROTECTIVE_STOP, frozenset({"occupancy"}))
    assert stopped_leaves([seeing], stop) == [seeing]
    hold[0] = stop
    assert handler.started.wait(5.0)
    assert executor.held == "" and tree.nodes["watch"].status is FAILURE
    hold[0] = None
    handler.job.succeed()
    result = executor.wait(5.0)
    assert result is not None and result.status is SUCCESS
