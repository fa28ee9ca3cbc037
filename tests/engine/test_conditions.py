"""Pre- and post-conditions of any node and the SKIPPED status, as BehaviorTree.CPP 4.10 runs
them (src/tree_node.cpp). The cases follow the situations of its own tests
(gtest_preconditions.cpp, gtest_postconditions.cpp, gtest_skipping.cpp), said again for this
engine: a counting leaf stands for their TestA/TestB, a leaf that keeps running for their
KeepRunning, a Script leaf for their Script nodes.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, rooted, with_children

from engine.catch import Catch
from engine.composites import (
    Parallel,
    ParallelPolicy,
    ReactiveSequence,
    Selector,
    Sequence,
)
from engine.conditions import Condition, NodeConditions
from engine.decorators import ForceSuccess, Inverter, Iterator, Repeat, Retry, Timeout
from engine.error_types import ErrorType
from engine.leaves import ScriptLeaf
from engine.node import Node
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status
from engine.tree import RunPolicy


def given(node: Node, **texts: str) -> Node:
    """``node`` with conditions (keyword: the condition's file key, ``while_`` for while)."""
    conditions = {Condition(key.rstrip("_")): text for key, text in texts.items()}
    node.conditions = NodeConditions(conditions, node.ctx.blackboard, writer=node.id)
    return node


def counting(ctx: Any, name: str, *statuses: Status, **texts: str) -> ScriptedLeaf:
    leaf = ScriptedLeaf(ctx, name, *(statuses or (SUCCESS,)))
    given(leaf, **texts)
    return leaf


def script(ctx: Any, code: str, name: str = "s") -> ScriptLeaf:
    return ScriptLeaf(ctx, name, name, code)


def seq(ctx: Any, *children: Node, name: str = "seq") -> Node:
    return with_children(Sequence(ctx, name, name), children)


def board(ctx: Any) -> dict[str, Any]:
    return dict(ctx.blackboard.snapshot())


# ---------------------------------------------------------------- pre-conditions


def test_success_if_and_failure_if_give_their_result_without_running_the_node(ctx: Any) -> None:
    a = counting(ctx, "a", success_if="A == 1")
    b = counting(ctx, "b", success_if="A == 2")
    c = counting(ctx, "c", failure_if="A == 1")
    d = counting(ctx, "d", failure_if="A != 1")
    fallback = with_children(Selector(ctx, "fb", "fb"), [c, d])
    tree = rooted(ctx, seq(ctx, script(ctx, "A := 1"), a, b, fallback))
    assert tree.tick_until_done() is SUCCESS
    assert (a.updates, b.updates, c.updates, d.updates) == (0, 1, 0, 1)
    assert c.status is FAILURE and c.error is ErrorType.FAILED
    assert "failure condition (A == 1)" in c.message


def test_the_first_pre_condition_that_holds_decides_in_failure_success_skip_order(
    ctx: Any,
) -> None:
    a = counting(ctx, "a", success_if="A == 2", failure_if="A != 1", skip_if="A == 1")
    b = counting(ctx, "b")
    tree = rooted(ctx, seq(ctx, script(ctx, "A := 1"), a, b))
    assert tree.tick_until_done() is SUCCESS
    assert a.status is SKIPPED and a.updates == 0 and b.updates == 1
    # failure_if comes first: with A == 2 it holds before success_if is looked at
    for value, expected in ((1, SKIPPED), (2, FAILURE), (3, FAILURE)):
        node = counting(ctx, "x", success_if="A == 2", failure_if="A != 1", skip_if="A == 1")
        ctx.blackboard.set("A", value)
        assert node.tick() is expected and node.updates == 0
    both = counting(ctx, "y", success_if="true", skip_if="true")
    assert both.tick() is SUCCESS


def test_skip_conditions_are_checked_in_tick_order_after_earlier_post_conditions(
    ctx: Any,
) -> None:
    """A chain where each node's on_success makes the one before it run on the next round."""
    a = counting(ctx, "a", skip_if="A != 1")
    b = counting(ctx, "b", skip_if="A != 2", on_success="A = 1")
    c = counting(ctx, "c", skip_if="A != 3", on_success="A = 2")
    tree = rooted(ctx, seq(ctx, a, b, c))
    ctx.blackboard.set("A", 3)
    counts = []
    for _ in range(3):
        tree.reset()
        assert tree.tick() is SUCCESS
        counts.append((a.updates, b.updates, c.updates))
    assert counts == [(0, 0, 1), (0, 1, 1), (1, 1, 1)]


def test_a_skipped_node_never_starts_its_work(ctx: Any) -> None:
    long_job = counting(ctx, "job", RUNNING, skip_if="A == 1")
    tree = rooted(ctx, seq(ctx, script(ctx, "A := 1"), long_job))
    assert tree.tick_until_done() is SUCCESS
    assert long_job.updates == 0 and long_job.status is SKIPPED


def test_skip_if_is_not_checked_again_while_a_decorator_runs(ctx: Any) -> None:
    forever = given(
        with_children(Iterator(ctx, "loop", "loop"), [counting(ctx, "ok")]), skip_if="check"
    )
    tree = rooted(ctx, forever)
    ctx.blackboard.set("check", False)
    assert tree.tick() is RUNNING
    ctx.blackboard.set("check", True)
    assert tree.tick() is RUNNING


def test_skip_if_is_checked_when_idle_only(ctx: Any) -> None:
    keep = counting(ctx, "keep", RUNNING, skip_if="check == false")
    tree = rooted(ctx, keep)
    ctx.blackboard.set("check", False)
    assert tree.tick() is SKIPPED and keep.updates == 0
    ctx.blackboard.set("check", True)
    tree.reset()
    assert tree.tick() is RUNNING
    ctx.blackboard.set("check", False)
    assert tree.tick() is RUNNING and keep.updates == 2


def test_a_sequence_of_one_skipped_child_is_skipped_and_runs_once_not_skipped(ctx: Any) -> None:
    ok = counting(ctx, "ok", skip_if="skip")
    tree = rooted(ctx, seq(ctx, ok))
    results = []
    for skip in (True, False, True, False):
        ctx.blackboard.set("skip", skip)
        tree.reset()
        results.append(tree.tick_until_done())
    assert results == [SKIPPED, SUCCESS, SKIPPED, SUCCESS]
    assert ok.updates == 2


def test_while_false_before_the_start_skips(ctx: Any) -> None:
    for doit, ticks in ((True, 1), (False, 0)):
        leaf = counting(ctx, "t", while_="doit")
        inner = seq(ctx, leaf, name="inner")
        tree = rooted(ctx, seq(ctx, script(ctx, f"doit := {str(doit).lower()}"), inner))
        assert tree.tick_until_done() is SUCCESS
        assert leaf.updates == ticks
        assert inner.status is (SUCCESS if doit else SKIPPED)


def test_while_turning_false_halts_the_running_node_runs_on_halted_and_skips(ctx: Any) -> None:
    keep = counting(ctx, "keep", RUNNING, while_="A == 1", on_halted="B = 69")
    top = seq(ctx, keep)
    tree = rooted(ctx, top)
    ctx.blackboard.set("A", 1)
    ctx.blackboard.set("B", 0)
    assert tree.tick() is RUNNING and board(ctx)["B"] == 0
    ctx.blackboard.set("A", 0)
    assert tree.tick() is SKIPPED
    assert board(ctx)["B"] == 69 and keep.halts == 1
    assert keep.status is SKIPPED and top.status is SKIPPED
    assert [c for c in ctx.changes if c[0] == "keep"] == [
        ("keep", IDLE, RUNNING),
        ("keep", RUNNING, IDLE),
        ("keep", IDLE, SKIPPED),
    ]


def test_while_is_checked_on_every_tick_but_the_other_pre_conditions_only_at_the_start(
    ctx: Any,
) -> None:
    keep = counting(ctx, "keep", RUNNING, while_="B == 0")
    guarded = given(with_children(ForceSuccess(ctx, "g", "g"), [keep]), failure_if="A != 0")
    tree = rooted(ctx, seq(ctx, script(ctx, "A := 0"), script(ctx, "B := 0", "b"), guarded))
    assert tree.tick() is RUNNING
    ctx.blackboard.set("A", 1)  # the decorator runs: its failure_if is not checked again
    assert tree.tick() is RUNNING
    ctx.blackboard.set("B", 1)
    assert tree.tick() is SUCCESS
    assert keep.status is SKIPPED and guarded.status is SKIPPED


def test_a_repeated_child_checks_its_pre_conditions_again_each_round(ctx: Any) -> None:
    a = counting(ctx, "a", skip_if="A != 0")
    keep = counting(ctx, "keep", RUNNING, while_="B == 0")
    body = seq(ctx, a, counting(ctx, "b"), keep, name="body")
    tree = rooted(ctx, with_children(Repeat(ctx, "r", "r", count=3), [body]))
    ctx.blackboard.set("A", 0)
    ctx.blackboard.set("B", 0)
    assert tree.tick() is RUNNING and a.updates == 1
    ctx.blackboard.set("A", 1)
    ctx.blackboard.set("B", 1)
    # keep is halted and skipped: round 1 succeeds, and round 2 (a and keep skipped) runs in
    # the same tick, as BehaviorTree.CPP's Repeat starts a child that had been running again
    assert tree.tick() is RUNNING and a.updates == 1
    ctx.blackboard.set("A", 0)
    assert tree.tick() is SUCCESS and a.updates == 2 and keep.halts == 1


def test_a_script_that_fails_in_a_pre_condition_fails_the_node(ctx: Any) -> None:
    node = counting(ctx, "n", skip_if="missing == 1")
    assert node.tick() is FAILURE and node.updates == 0
    assert node.error is ErrorType.INVALID_INPUT
    assert node.message.startswith("skip if script line 1, column 1")


def test_a_while_that_fails_while_running_halts_the_node(ctx: Any) -> None:
    node = counting(ctx, "n", RUNNING, while_="go")
    ctx.blackboard.set("go", True)
    assert node.tick() is RUNNING
    ctx.blackboard.unset("go")
    assert node.tick() is FAILURE and node.halts == 1 and node.error is ErrorType.INVALID_INPUT


# ---------------------------------------------------------------- post-conditions


def test_on_success_and_on_failure_run_after_results_a_pre_condition_gave_too(ctx: Any) -> None:
    ok = counting(ctx, "ok", on_success="B = 42")
    refused = given(counting(ctx, "r"), failure_if="A != 0", on_failure="C = 42")
    failing = counting(ctx, "f", FAILURE, on_failure="D = 42")
    tree = rooted(
        ctx,
        seq(
            ctx,
            script(ctx, "A := 1; B := 1; C := 1; D := 1"),
            ok,
            with_children(ForceSuccess(ctx, "fs1", "fs1"), [refused]),
            with_children(ForceSuccess(ctx, "fs2", "fs2"), [failing]),
        ),
    )
    assert tree.tick_until_done() is SUCCESS
    assert {k: board(ctx)[k] for k in "BCD"} == {"B": 42, "C": 42, "D": 42}


def test_on_failure_and_post_run_after_every_try_of_a_retry(ctx: Any) -> None:
    failing = counting(ctx, "f", FAILURE, on_failure="x += 1", post="y += 1")
    tree = rooted(
        ctx,
        seq(ctx, script(ctx, "x := 0; y := 0"), with_children(Retry(ctx, "r", "r", 5), [failing])),
    )
    assert tree.tick_until_done() is FAILURE
    assert (board(ctx)["x"], board(ctx)["y"]) == (5, 5)


def test_a_halted_node_runs_on_halted_and_not_post(ctx: Any) -> None:
    sleeping = counting(ctx, "sleep", RUNNING, on_halted="test = 'halted'", post="test = 'post'")
    both = with_children(
        Parallel(ctx, "p", "p", ParallelPolicy("all", 1)), [sleeping, counting(ctx, "f", FAILURE)]
    )
    tree = rooted(ctx, seq(ctx, script(ctx, "test := 'start'"), both))
    assert tree.tick_until_done() is FAILURE
    assert board(ctx)["test"] == "halted" and sleeping.halts == 1


def test_post_runs_after_success_and_failure_not_after_skipped(ctx: Any) -> None:
    ctx.blackboard.set("n", 0)
    for status in (SUCCESS, FAILURE):
        node = counting(ctx, "x", status, post="n += 1")
        assert node.tick() is status
    skipped = counting(ctx, "s", skip_if="true", post="n += 1")
    assert skipped.tick() is SKIPPED
    assert board(ctx)["n"] == 2


def test_a_failing_post_condition_fails_the_node(ctx: Any) -> None:
    node = counting(ctx, "x", on_success="nothing = 1")
    assert node.tick() is FAILURE
    assert node.message.startswith("on success script") and node.error is ErrorType.INVALID_INPUT


def test_a_failing_on_halted_is_a_log_line_and_a_throw_runs_on_halted(ctx: Any) -> None:
    node = counting(ctx, "x", RUNNING, on_halted="nothing = 1")
    node.tick()
    node.reset()
    assert node.status is IDLE and ctx.logs[-1][1].startswith("on halted script")
    thrown = counting(ctx, "t", RUNNING, on_halted="stopped := true")
    thrown.tick()
    thrown.abort("the cell stopped", ErrorType.FAILED)
    assert thrown.status is FAILURE and board(ctx)["stopped"] is True


# ---------------------------------------------------------------- SKIPPED in parents


def test_every_child_skipped_skips_the_sequence_and_the_run(ctx: Any) -> None:
    leaves = [
        counting(ctx, "a", skip_if="A == 1"),
        counting(ctx, "b", skip_if="A < 2"),
        counting(ctx, "c", skip_if="A > 0"),
    ]
    tree = rooted(ctx, seq(ctx, *leaves))
    ctx.blackboard.set("A", 1)
    assert tree.tick_until_done() is SKIPPED
    assert [leaf.updates for leaf in leaves] == [0, 0, 0]
    assert tree.root.message == "every child was skipped"


def test_a_selector_goes_on_past_a_skipped_child(ctx: Any) -> None:
    skipped = counting(ctx, "s", skip_if="true")
    failed = counting(ctx, "f", FAILURE)
    selector = with_children(Selector(ctx, "sel", "sel"), [skipped, failed])
    assert selector.tick() is FAILURE
    selector.reset()
    failed.set_script(SUCCESS)
    assert selector.tick() is SUCCESS and skipped.updates == 0
    only_skipped = with_children(Selector(ctx, "o", "o"), [counting(ctx, "z", skip_if="true")])
    assert only_skipped.tick() is SKIPPED


def test_a_skipped_subtree_of_a_sequence_is_passed_over(ctx: Any) -> None:
    a = counting(ctx, "a")
    inner = given(seq(ctx, counting(ctx, "b"), name="sub"), skip_if="data")
    tree = rooted(ctx, seq(ctx, a, script(ctx, "data := true"), inner))
    assert tree.tick_until_done() is SUCCESS
    assert a.updates == 1 and inner.children[0].status is IDLE


def test_a_reactive_sequence_of_one_skipped_child_is_skipped(ctx: Any) -> None:
    ctx.blackboard.set("flag", True)
    tree = rooted(
        ctx,
        with_children(ReactiveSequence(ctx, "r", "r"), [counting(ctx, "ok", skip_if="flag")]),
    )
    assert tree.tick_until_done() is SKIPPED


@pytest.mark.parametrize("value, checked", [(50, True), (10, False)])
def test_a_reactive_sequence_checks_a_skipped_child_again_each_tick(
    ctx: Any, value: int, checked: bool
) -> None:
    check = ScriptedLeaf(ctx, "check", SUCCESS, condition=True)
    given(check, skip_if="value < 25")
    work = ScriptedLeaf(ctx, "work", RUNNING, RUNNING, SUCCESS)
    tree = rooted(
        ctx,
        with_children(
            ReactiveSequence(ctx, "r", "r"), [script(ctx, f"value := {value}"), check, work]
        ),
    )
    ticks = 0
    for _ in range(3):
        tree.reset()
        work.set_script(RUNNING, RUNNING, SUCCESS)
        status = RUNNING
        while status is RUNNING:
            status = tree.tick()
            ticks += 1
        assert status is SUCCESS
    assert check.updates == (ticks if checked else 0)


def test_a_skipped_child_of_a_reactive_sequence_can_start_when_its_condition_changes(
    ctx: Any,
) -> None:
    late = counting(ctx, "late", skip_if="!ready")
    work = ScriptedLeaf(ctx, "work", RUNNING)
    tree = rooted(ctx, with_children(ReactiveSequence(ctx, "r", "r"), [late, work]))
    ctx.blackboard.set("ready", False)
    assert tree.tick() is RUNNING and late.status is SKIPPED
    ctx.blackboard.set("ready", True)
    assert tree.tick() is RUNNING and late.status is SUCCESS and late.updates == 1


def test_a_parallel_counts_skipped_children_as_done_for_all_and_skips_when_all_skip(
    ctx: Any,
) -> None:
    def parallel(policy: ParallelPolicy, *children: Node) -> Node:
        return with_children(Parallel(ctx, "p", "p", policy), children)

    mixed = parallel(ParallelPolicy("all"), counting(ctx, "a"), counting(ctx, "b", skip_if="true"))
    assert mixed.tick() is SUCCESS
    everything = parallel(ParallelPolicy("any"), counting(ctx, "c", skip_if="true"))
    assert everything.tick() is SKIPPED
    waiting = parallel(ParallelPolicy("any"), counting(ctx, "d", skip_if="!go"))
    ctx.blackboard.set("go", False)
    assert waiting.tick() is SKIPPED


@pytest.mark.parametrize(
    "decorator",
    [
        lambda ctx: Inverter(ctx, "d", "d"),
        lambda ctx: ForceSuccess(ctx, "d", "d"),
        lambda ctx: Repeat(ctx, "d", "d", 3),
        lambda ctx: Retry(ctx, "d", "d", 3),
        lambda ctx: Timeout(ctx, "d", "d", 5.0),
        lambda ctx: Iterator(ctx, "d", "d"),
    ],
)
def test_decorators_pass_skipped_up(ctx: Any, decorator: Any) -> None:
    node = with_children(decorator(ctx), [counting(ctx, "x", skip_if="true")])
    assert node.tick() is SKIPPED


def test_a_catch_whose_handler_is_skipped_fails_as_its_body_did(ctx: Any) -> None:
    body = counting(ctx, "body", FAILURE)
    body.message = ""
    handler = counting(ctx, "handler", skip_if="true")
    catch = with_children(Catch(ctx, "c", "c"), [body, handler])
    assert catch.tick() is FAILURE and "handler was skipped" in catch.message
    skipped_body = with_children(
        Catch(ctx, "c2", "c2"), [counting(ctx, "b2", skip_if="true"), counting(ctx, "h2")]
    )
    assert skipped_body.tick() is SKIPPED


@pytest.mark.parametrize(
    "policy, expected", [(RunPolicy.ONCE, SKIPPED), (RunPolicy.UNTIL_SUCCESS, SKIPPED)]
)
def test_a_skipped_run_ends_once_and_until_success(
    ctx: Any, policy: RunPolicy, expected: Status
) -> None:
    tree = rooted(ctx, counting(ctx, "x", skip_if="true"), policy)
    assert tree.tick() is expected


def test_a_forever_run_starts_a_skipped_child_again(ctx: Any) -> None:
    leaf = counting(ctx, "x", skip_if="skip")
    ctx.blackboard.set("skip", True)
    tree = rooted(ctx, leaf, RunPolicy.FOREVER)
    assert tree.tick() is RUNNING and leaf.updates == 0
    ctx.blackboard.set("skip", False)
    assert tree.tick() is RUNNING and leaf.updates == 1


def test_skipped_latches_until_reset(ctx: Any) -> None:
    leaf = counting(ctx, "x", skip_if="skip")
    ctx.blackboard.set("skip", True)
    assert leaf.tick() is SKIPPED
    ctx.blackboard.set("skip", False)
    assert leaf.tick() is SKIPPED
    leaf.reset()
    assert leaf.status is IDLE and leaf.tick() is SUCCESS
