"""BehaviorTree.CPP 4.10's built-in nodes as runtime nodes, tick by tick, on the cases of its
own tests (tests/gtest_sequence, gtest_if_then_else, gtest_while_do_else, gtest_switch,
gtest_parallel, gtest_try_catch, gtest_decorator): the statuses of the node and of its
children after each tick, and what a halt does.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import FakeClock, ScriptedLeaf, with_children

from engine.blackboard_leaves import AlwaysFailure, AlwaysSuccess, SetBlackboard, UnsetBlackboard
from engine.composites import (
    AsyncFallback,
    AsyncSequence,
    Parallel,
    ParallelPolicy,
    SequenceWithMemory,
)
from engine.controls import IfThenElse, ParallelAll, Switch, TryCatch, WhileDoElse
from engine.decorators import Delay, KeepRunningUntilFailure, Precondition, RunOnce
from engine.error_types import ErrorType
from engine.port_text import same_text
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status


def leaves(ctx: Any, *scripts: tuple[Status, ...]) -> list[ScriptedLeaf]:
    return [ScriptedLeaf(ctx, f"c{i}", *script) for i, script in enumerate(scripts)]


def statuses(nodes: list[ScriptedLeaf]) -> list[Status]:
    return [node.status for node in nodes]


# ---------------------------------------------------------------------- leaves


def test_always_success_and_always_failure_answer_at_once(ctx: Any) -> None:
    assert AlwaysSuccess(ctx, "s").tick() is SUCCESS
    failing = AlwaysFailure(ctx, "f")
    assert failing.tick() is FAILURE and failing.error is ErrorType.FAILED


def test_set_blackboard_writes_text_copies_an_entry_and_converts_to_a_number(ctx: Any) -> None:
    board = ctx.blackboard
    assert SetBlackboard(ctx, "a", "", "hello", "greeting").tick() is SUCCESS
    assert SetBlackboard(ctx, "b", "", "{greeting}", "copy").tick() is SUCCESS
    board.set("count", 3)
    assert SetBlackboard(ctx, "c", "", "42", "count").tick() is SUCCESS
    assert board.snapshot() == {"greeting": "hello", "copy": "hello", "count": 42}
    assert SetBlackboard(ctx, "d", "", "7", "{ greeting }").tick() is SUCCESS
    assert board.get("hello") == "7"  # output_key {key}: the entry's value names the target


def test_set_blackboard_fails_on_a_missing_source_or_a_value_of_the_wrong_type(ctx: Any) -> None:
    missing = SetBlackboard(ctx, "a", "", "{nothing}", "out")
    assert missing.tick() is FAILURE and missing.error is ErrorType.INVALID_INPUT
    ctx.blackboard.set("n", 1.5)
    wrong = SetBlackboard(ctx, "b", "", "many", "n")
    assert wrong.tick() is FAILURE and "number" in wrong.message
    assert "out" not in ctx.blackboard and ctx.blackboard.get("n") == 1.5


def test_set_blackboard_in_a_scope_and_at_the_top(ctx: Any) -> None:
    node = SetBlackboard(ctx, "a", "", "1", "x", key=lambda name: f"inner/{name}")
    assert node.tick() is SUCCESS and ctx.blackboard.get("inner/x") == "1"
    top = SetBlackboard(ctx, "b", "", "2", "@x", key=lambda name: f"inner/{name}")
    assert top.tick() is SUCCESS and ctx.blackboard.get("x") == "2"


def test_unset_blackboard_removes_an_entry_and_succeeds_without_one(ctx: Any) -> None:
    ctx.blackboard.set("x", 1)
    assert UnsetBlackboard(ctx, "u", "", "x").tick() is SUCCESS
    assert "x" not in ctx.blackboard
    assert UnsetBlackboard(ctx, "v", "", "x").tick() is SUCCESS


# ---------------------------------------------------------------------- sequences


def test_sequence_with_memory_resumes_at_the_child_that_failed(ctx: Any) -> None:
    first, second, third = leaves(ctx, (SUCCESS,), (FAILURE, SUCCESS), (SUCCESS,))
    node = with_children(SequenceWithMemory(ctx, "s"), [first, second, third])
    assert node.tick() is RUNNING  # like an AsyncSequence: the tick back after first
    assert node.tick() is FAILURE
    assert statuses([first, second, third]) == [SUCCESS, FAILURE, IDLE]
    node.reset()  # a retry: BehaviorTree.CPP's halt keeps the place
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]
    assert (first.updates, second.updates, third.updates) == (1, 2, 1)
    node.reset()  # after a success it starts from the first child again
    assert node.tick() is RUNNING and first.updates == 2


def test_sequence_with_memory_keeps_its_place_through_a_halt(ctx: Any) -> None:
    first, second = leaves(ctx, (SUCCESS,), (RUNNING, SUCCESS))
    node = with_children(SequenceWithMemory(ctx, "s"), [first, second])
    assert [node.tick(), node.tick()] == [RUNNING, RUNNING] and second.status is RUNNING
    node.reset()
    assert second.halts == 1
    assert node.tick() is SUCCESS and first.updates == 1


def test_async_sequence_gives_the_tick_back_after_each_immediate_success(ctx: Any) -> None:
    first, second, third = leaves(ctx, (SUCCESS,), (RUNNING, SUCCESS), (SUCCESS,))
    node = with_children(AsyncSequence(ctx, "a"), [first, second, third])
    wakes: list[int] = []
    ctx.wake = lambda: wakes.append(1)
    assert node.tick() is RUNNING and statuses([first, second, third]) == [SUCCESS, IDLE, IDLE]
    assert wakes == [1]  # BehaviorTree.CPP's wake-up signal: the next tick comes at once
    assert node.tick() is RUNNING and second.status is RUNNING
    # second finishes after running: no tick is given back, third runs in the same tick
    assert node.tick() is SUCCESS and third.status is SUCCESS


def test_async_fallback_gives_the_tick_back_after_each_immediate_failure(ctx: Any) -> None:
    first, second = leaves(ctx, (FAILURE,), (SUCCESS,))
    node = with_children(AsyncFallback(ctx, "a"), [first, second])
    assert node.tick() is RUNNING and second.status is IDLE
    assert node.tick() is SUCCESS


# ---------------------------------------------------------------------- IfThenElse, WhileDoElse


@pytest.mark.parametrize(
    ("condition", "expected", "ran"),
    [(SUCCESS, SUCCESS, [SUCCESS, IDLE]), (FAILURE, FAILURE, [IDLE, FAILURE])],
)
def test_if_then_else_runs_one_branch(
    ctx: Any, condition: Status, expected: Status, ran: list[Status]
) -> None:
    cond, then, other = leaves(ctx, (condition,), (SUCCESS,), (FAILURE,))
    node = with_children(IfThenElse(ctx, "i"), [cond, then, other])
    assert node.tick() is expected and statuses([then, other]) == ran


def test_if_then_else_without_else_fails_and_waits_for_a_running_condition(ctx: Any) -> None:
    cond, then = leaves(ctx, (RUNNING, FAILURE), (SUCCESS,))
    node = with_children(IfThenElse(ctx, "i"), [cond, then])
    assert node.tick() is RUNNING and then.status is IDLE
    assert node.tick() is FAILURE and then.updates == 0


def test_if_then_else_does_not_check_its_condition_again_while_a_branch_runs(ctx: Any) -> None:
    cond, then, other = leaves(ctx, (SUCCESS, FAILURE), (RUNNING, RUNNING, SUCCESS), (SUCCESS,))
    node = with_children(IfThenElse(ctx, "i"), [cond, then, other])
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert cond.updates == 1 and other.updates == 0
    node.reset()
    assert node.tick() is SUCCESS and other.status is SUCCESS  # the condition now fails


def test_if_then_else_halt_halts_the_running_branch(ctx: Any) -> None:
    cond, then = leaves(ctx, (SUCCESS,), (RUNNING,))
    node = with_children(IfThenElse(ctx, "i"), [cond, then])
    assert node.tick() is RUNNING
    node.reset()
    assert then.halts == 1 and statuses([cond, then]) == [IDLE, IDLE]


def test_while_do_else_rechecks_its_condition_and_halts_the_other_branch(ctx: Any) -> None:
    cond, do, other = leaves(ctx, (SUCCESS, FAILURE, SUCCESS), (RUNNING,), (RUNNING,))
    node = with_children(WhileDoElse(ctx, "w"), [cond, do, other])
    assert node.tick() is RUNNING and statuses([do, other]) == [RUNNING, IDLE]
    assert node.tick() is RUNNING and statuses([do, other]) == [IDLE, RUNNING]
    assert do.halts == 1
    assert node.tick() is RUNNING and statuses([do, other]) == [RUNNING, IDLE]
    assert other.halts == 1 and cond.updates == 3


def test_while_do_else_with_two_children_fails_and_halts_do(ctx: Any) -> None:
    cond, do = leaves(ctx, (SUCCESS, FAILURE), (RUNNING,))
    node = with_children(WhileDoElse(ctx, "w"), [cond, do])
    assert node.tick() is RUNNING
    assert node.tick() is FAILURE and do.status is IDLE and do.halts == 1


def test_while_do_else_gives_the_branch_result(ctx: Any) -> None:
    cond, do, other = leaves(ctx, (FAILURE,), (SUCCESS,), (FAILURE,))
    node = with_children(WhileDoElse(ctx, "w"), [cond, do, other])
    assert node.tick() is FAILURE and do.status is IDLE


# ---------------------------------------------------------------------- Switch


def switch(ctx: Any, *cases: str) -> tuple[Switch, list[ScriptedLeaf]]:
    children = leaves(ctx, *[(RUNNING,)] * (len(cases) + 1))
    node = Switch(ctx, "sw", "", "{my_var}", cases)
    node.set_children(children)
    return node, children


@pytest.mark.parametrize(
    ("value", "running"),
    [("1", 0), ("42", 1), ("42.0", 1), ("", 2), ("nope", 2), (None, 2), (42, 1)],
)
def test_switch_runs_the_matching_case_else_the_default(ctx: Any, value: Any, running: int) -> None:
    if value is not None:
        ctx.blackboard.set("my_var", value)
    node, children = switch(ctx, "1", "42")
    assert node.tick() is RUNNING
    assert [c.status is RUNNING for c in children] == [i == running for i in range(3)]


def test_switch_halts_the_running_case_when_the_variable_changes(ctx: Any) -> None:
    ctx.blackboard.set("my_var", "1")
    node, (one, forty_two, default) = switch(ctx, "1", "42")
    assert node.tick() is RUNNING and one.status is RUNNING
    ctx.blackboard.set("my_var", "")
    assert one.status is RUNNING  # not reactive: nothing changes until the next tick
    assert node.tick() is RUNNING
    assert statuses([one, forty_two, default]) == [IDLE, IDLE, RUNNING] and one.halts == 1
    default.set_script(SUCCESS)
    assert node.tick() is SUCCESS


def test_switch_gives_a_failing_case_result(ctx: Any) -> None:
    ctx.blackboard.set("my_var", "1")
    node, (one, *_) = switch(ctx, "1", "42")
    one.set_script(FAILURE)
    assert node.tick() is FAILURE


def test_switch_string_equality_rejects_trailing_characters() -> None:
    assert same_text("1", "1.0") and same_text("-3", "-3") and same_text("0.1", "0.10")
    assert not same_text("1", "1abc") and not same_text("42", "42 ") and not same_text("1", "2")
    assert same_text("RED", "0", {"RED": 0})


# ---------------------------------------------------------------------- Parallel, ParallelAll


def test_parallel_negative_counts_count_back_from_all_children(ctx: Any) -> None:
    children = leaves(ctx, (SUCCESS,), (SUCCESS,), (RUNNING,))
    node = with_children(Parallel(ctx, "p", policy=ParallelPolicy(-2, -3)), children)
    assert node.tick() is SUCCESS  # -2 of 3: two successes, and the third is not started
    assert children[2].status is IDLE and children[2].updates == 0
    failing = leaves(ctx, (FAILURE,), (FAILURE,), (RUNNING,))
    node = with_children(Parallel(ctx, "q", policy=ParallelPolicy("all", -2)), failing)
    assert node.tick() is FAILURE  # -2 of 3: two failures


def test_parallel_checks_its_policy_after_each_child_counting_earlier_results(ctx: Any) -> None:
    first, second, third = leaves(ctx, (RUNNING, SUCCESS), (SUCCESS,), (RUNNING,))
    node = with_children(Parallel(ctx, "p", policy=ParallelPolicy(2)), [first, second, third])
    assert node.tick() is RUNNING and third.status is RUNNING
    # first's success with second's from the last tick meets the policy: third is halted
    # and not ticked again (BehaviorTree.CPP keeps the count of earlier successes)
    assert node.tick() is SUCCESS and (third.updates, third.halts) == (1, 1)


def test_parallel_all_waits_for_every_child_then_counts_failures(ctx: Any) -> None:
    children = leaves(ctx, (FAILURE,), (RUNNING, SUCCESS), (SUCCESS,))
    node = with_children(ParallelAll(ctx, "p", max_failures=1), children)
    assert node.tick() is RUNNING
    assert node.tick() is FAILURE and children[1].updates == 2 and children[0].updates == 1


@pytest.mark.parametrize(("max_failures", "expected"), [(2, SUCCESS), (-2, SUCCESS), (-3, FAILURE)])
def test_parallel_all_max_failures(ctx: Any, max_failures: int, expected: Status) -> None:
    children = leaves(ctx, (FAILURE,), (SUCCESS,), (SUCCESS,))
    node = with_children(ParallelAll(ctx, "p", max_failures=max_failures), children)
    assert node.tick() is expected


def test_parallel_all_is_skipped_when_every_child_was(ctx: Any) -> None:
    children = leaves(ctx, (SKIPPED,), (SKIPPED,))
    assert with_children(ParallelAll(ctx, "p"), children).tick() is SKIPPED


# ---------------------------------------------------------------------- TryCatch


def test_try_catch_succeeds_when_the_try_block_does(ctx: Any) -> None:
    first, second, catch = leaves(ctx, (SUCCESS,), (SUCCESS,), (SUCCESS,))
    node = with_children(TryCatch(ctx, "t"), [first, second, catch])
    assert node.tick() is SUCCESS and catch.updates == 0


@pytest.mark.parametrize("catch_result", [SUCCESS, FAILURE])
def test_try_catch_runs_the_catch_and_fails_whatever_it_gave(
    ctx: Any, catch_result: Status
) -> None:
    first, second, third, catch = leaves(ctx, (SUCCESS,), (FAILURE,), (SUCCESS,), (catch_result,))
    node = with_children(TryCatch(ctx, "t"), [first, second, third, catch])
    assert node.tick() is FAILURE
    assert catch.updates == 1 and third.updates == 0 and "c1 failed" in node.message


def test_try_catch_waits_for_a_running_try_child_and_a_running_catch(ctx: Any) -> None:
    body, catch = leaves(ctx, (RUNNING, FAILURE), (RUNNING, SUCCESS))
    node = with_children(TryCatch(ctx, "t"), [body, catch])
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, FAILURE]
    assert body.updates == 2 and catch.updates == 2


@pytest.mark.parametrize(("on_halt", "catches"), [(False, 0), (True, 1)])
def test_try_catch_catch_on_halt(ctx: Any, on_halt: bool, catches: int) -> None:
    body, catch = leaves(ctx, (RUNNING,), (SUCCESS,))
    node = with_children(TryCatch(ctx, "t", catch_on_halt=on_halt), [body, catch])
    assert node.tick() is RUNNING
    node.reset()
    assert catch.updates == catches and body.halts == 1
    assert statuses([body, catch]) == [IDLE, IDLE]


def test_try_catch_catch_on_halt_halts_a_catch_that_runs_and_not_twice(ctx: Any) -> None:
    body, catch = leaves(ctx, (RUNNING,), (RUNNING,))
    node = with_children(TryCatch(ctx, "t", catch_on_halt=True), [body, catch])
    node.tick()
    node.reset()
    assert (catch.updates, catch.halts) == (1, 1)
    body.set_script(FAILURE)
    assert node.tick() is RUNNING  # now in the catch
    node.reset()
    assert (catch.updates, catch.halts) == (2, 2)  # halted, not run again on halt


# ---------------------------------------------------------------------- decorators


def test_keep_running_until_failure(ctx: Any) -> None:
    (child,) = leaves(ctx, (SUCCESS, RUNNING, SUCCESS, FAILURE))
    node = with_children(KeepRunningUntilFailure(ctx, "k"), [child])
    assert [node.tick() for _ in range(4)] == [RUNNING, RUNNING, RUNNING, FAILURE]
    assert child.resets == 2


def test_delay_runs_the_child_after_its_time(ctx: Any, clock: FakeClock) -> None:
    (child,) = leaves(ctx, (SUCCESS,))
    node = with_children(Delay(ctx, "d", seconds=0.1), [child])
    assert node.tick() is RUNNING
    clock.advance(0.05)
    assert node.tick() is RUNNING and child.updates == 0
    clock.advance(0.06)
    assert node.tick() is SUCCESS and child.updates == 1


def test_delay_of_zero_still_gives_one_tick_back(ctx: Any) -> None:
    (child,) = leaves(ctx, (SUCCESS,))
    node = with_children(Delay(ctx, "d", seconds=0.0), [child])
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]


@pytest.mark.parametrize(("then_skip", "again"), [(True, SKIPPED), (False, FAILURE)])
def test_run_once(ctx: Any, then_skip: bool, again: Status) -> None:
    (child,) = leaves(ctx, (RUNNING, FAILURE))
    node = with_children(RunOnce(ctx, "r", then_skip=then_skip), [child])
    assert [node.tick(), node.tick()] == [RUNNING, FAILURE]
    node.reset()
    assert node.tick() is again and child.updates == 2


def test_precondition_ticks_its_child_when_the_script_holds(ctx: Any) -> None:
    ctx.blackboard.set("a", 1)
    (child,) = leaves(ctx, (RUNNING, SUCCESS))
    node = with_children(Precondition(ctx, "p", "", "a == 1"), [child])
    assert node.tick() is RUNNING
    ctx.blackboard.set("a", 2)
    assert node.tick() is SUCCESS  # not checked again while the child runs
    node.reset()
    assert node.tick() is FAILURE and "a == 1" in node.message


@pytest.mark.parametrize("otherwise", [SUCCESS, SKIPPED, RUNNING])
def test_precondition_else(ctx: Any, otherwise: Status) -> None:
    (child,) = leaves(ctx, (SUCCESS,))
    node = with_children(Precondition(ctx, "p", "", "false", otherwise), [child])
    assert node.tick() is otherwise and child.updates == 0


def test_precondition_of_a_missing_entry_fails_as_invalid_input(ctx: Any) -> None:
    (child,) = leaves(ctx, (SUCCESS,))
    node = with_children(Precondition(ctx, "p", "", "missing == 1"), [child])
    assert node.tick() is FAILURE and node.error is ErrorType.INVALID_INPUT


def test_precondition_halted_while_its_child_runs_does_not_check_again(ctx: Any) -> None:
    ctx.blackboard.set("a", 1)
    (child,) = leaves(ctx, (RUNNING, SUCCESS))
    node = with_children(Precondition(ctx, "p", "", "a == 1"), [child])
    assert node.tick() is RUNNING
    node.reset()
    ctx.blackboard.set("a", 2)
    assert node.tick() is SUCCESS  # BehaviorTree.CPP's halt keeps _children_running too
