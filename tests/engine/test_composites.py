"""Sequence, Selector, Parallel and the reactive composites."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import JobOperation, ScriptedLeaf, leaf, with_children

from engine.composites import (
    Parallel,
    ParallelPolicy,
    ReactiveSelector,
    ReactiveSequence,
    Selector,
    Sequence,
)
from engine.decorators import Inverter
from engine.node import Node
from engine.operations import OperationKind
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status


def scripted(ctx: Any, *scripts: tuple[Status, ...]) -> list[ScriptedLeaf]:
    return [ScriptedLeaf(ctx, f"c{i}", *script) for i, script in enumerate(scripts)]


def parallel(
    ctx: Any, children: list[Node], success: str | int = "all", failure: str | int = "any"
) -> Parallel:
    node = Parallel(ctx, "par", policy=ParallelPolicy(success, failure))
    node.set_children(children)
    return node


# ---------------------------------------------------------------------- Sequence / Selector


def test_sequence_resumes_the_running_child_without_reticking_finished_ones(ctx: Any) -> None:
    a, b, c = scripted(ctx, (SUCCESS,), (RUNNING, RUNNING, SUCCESS), (SUCCESS,))
    seq = with_children(Sequence(ctx, "seq"), [a, b, c])
    assert [seq.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert (a.updates, b.updates, c.updates) == (1, 3, 1)


def test_sequence_fails_at_the_first_failure_and_skips_the_rest(ctx: Any) -> None:
    a, b, c = scripted(ctx, (SUCCESS,), (FAILURE,), (SUCCESS,))
    seq = with_children(Sequence(ctx, "seq"), [a, b, c])
    assert seq.tick() is FAILURE
    assert seq.message == "c1 failed"
    assert c.updates == 0 and c.status is IDLE
    assert seq.tick() is FAILURE and b.updates == 1  # latched


def test_sequence_starts_over_after_reset(ctx: Any) -> None:
    a, b = scripted(ctx, (SUCCESS,), (FAILURE, SUCCESS))
    seq = with_children(Sequence(ctx, "seq"), [a, b])
    assert seq.tick() is FAILURE
    seq.reset()
    assert seq.tick() is SUCCESS
    assert (a.updates, b.updates) == (2, 2)


def test_selector_resumes_the_running_child_and_stops_at_success(ctx: Any) -> None:
    a, b, c = scripted(ctx, (FAILURE,), (RUNNING, SUCCESS), (SUCCESS,))
    sel = with_children(Selector(ctx, "sel"), [a, b, c])
    assert [sel.tick() for _ in range(3)] == [RUNNING, SUCCESS, SUCCESS]
    assert (a.updates, b.updates, c.updates) == (1, 2, 0)


def test_selector_fails_when_every_option_failed(ctx: Any) -> None:
    a, b = scripted(ctx, (FAILURE,), (RUNNING, FAILURE))
    sel = with_children(Selector(ctx, "sel"), [a, b])
    assert [sel.tick(), sel.tick()] == [RUNNING, FAILURE]
    assert sel.message == "every option failed"


@pytest.mark.parametrize(
    ("cls", "expected"),
    [
        (Sequence, SUCCESS),
        (Selector, FAILURE),
        (ReactiveSequence, SUCCESS),
        (ReactiveSelector, FAILURE),
        (Parallel, SUCCESS),
    ],
)
def test_empty_composites(ctx: Any, cls: type[Node], expected: Status) -> None:
    node = with_children(cls(ctx, "empty"), [])
    assert node.tick() is expected


# ---------------------------------------------------------------------- Parallel


def test_parallel_all_ticks_every_unfinished_child(ctx: Any) -> None:
    a, b = scripted(ctx, (SUCCESS,), (RUNNING, RUNNING, SUCCESS))
    par = parallel(ctx, [a, b])
    assert [par.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert (a.updates, b.updates) == (1, 3)


def test_parallel_any_succeeds_at_the_first_success_and_halts_the_rest(ctx: Any) -> None:
    a, b, c = scripted(ctx, (RUNNING,), (RUNNING, SUCCESS), (RUNNING,))
    par = parallel(ctx, [a, b, c], success="any")
    assert [par.tick(), par.tick()] == [RUNNING, SUCCESS]
    assert (a.halts, c.halts) == (1, 1)
    assert (a.status, b.status, c.status) == (IDLE, SUCCESS, IDLE)


def test_parallel_success_count(ctx: Any) -> None:
    a, b, c = scripted(ctx, (SUCCESS,), (RUNNING,), (RUNNING, SUCCESS))
    par = parallel(ctx, [a, b, c], success=2)
    assert [par.tick(), par.tick()] == [RUNNING, SUCCESS]
    assert b.halts == 1


def test_parallel_failure_any_halts_the_running_children(ctx: Any) -> None:
    a, b = scripted(ctx, (RUNNING,), (RUNNING, FAILURE))
    par = parallel(ctx, [a, b])
    assert [par.tick(), par.tick()] == [RUNNING, FAILURE]
    assert par.message == "1 of 2 failed"
    assert a.halts == 1 and a.status is IDLE


def test_parallel_failure_count(ctx: Any) -> None:
    a, b, c = scripted(ctx, (FAILURE,), (RUNNING, FAILURE), (RUNNING,))
    par = parallel(ctx, [a, b, c], success="any", failure=2)
    assert [par.tick(), par.tick()] == [RUNNING, FAILURE]
    assert par.message == "2 of 3 failed"
    assert c.halts == 1


def test_parallel_fails_as_soon_as_the_success_policy_is_impossible(ctx: Any) -> None:
    a, b, c = scripted(ctx, (FAILURE,), (RUNNING,), (RUNNING,))
    par = parallel(ctx, [a, b, c], success=3, failure=2)
    assert par.tick() is FAILURE
    assert "too many children failed" in par.message
    assert (b.updates, c.updates) == (0, 0)  # BehaviorTree.CPP's: decided after a, b not started


def test_parallel_needing_more_successes_than_children_fails(ctx: Any) -> None:
    a, b = scripted(ctx, (RUNNING,), (RUNNING,))
    par = parallel(ctx, [a, b], success=3, failure=5)
    assert par.tick() is FAILURE  # BehaviorTree.CPP refuses it: no child is started
    assert (a.updates, b.updates) == (0, 0)


def test_parallel_halts_each_running_job_exactly_once(ctx: Any) -> None:
    ops = [JobOperation() for _ in range(3)]
    leaves: list[Node] = [leaf(ctx, o, f"job{i}") for i, o in enumerate(ops)]
    par = parallel(ctx, leaves, success="any")
    top = with_children(Sequence(ctx, "top"), [par])
    assert top.tick() is RUNNING
    ops[1].job.succeed()
    assert top.tick() is SUCCESS
    top.tick()
    top.reset()
    par.reset()
    assert [o.job.cancels for o in ops] == [1, 0, 1]
    assert [len(o.jobs) for o in ops] == [1, 1, 1]


@pytest.mark.parametrize(
    ("success", "failure"), [("some", "any"), (0, "any"), ("all", "all"), ("all", 0)]
)
def test_parallel_policy_refuses_bad_values(success: Any, failure: Any) -> None:
    with pytest.raises(ValueError, match="policy must be"):
        ParallelPolicy(success, failure)


# ---------------------------------------------------------------------- reactive


def test_reactive_sequence_halts_the_running_action_when_its_condition_turns_false(
    ctx: Any,
) -> None:
    guard = ScriptedLeaf(ctx, "region clear", SUCCESS, condition=True)
    work = JobOperation()
    node = with_children(ReactiveSequence(ctx, "rs"), [guard, leaf(ctx, work, "move")])
    assert [node.tick(), node.tick()] == [RUNNING, RUNNING]
    assert guard.updates == 2  # re-checked every tick
    assert len(work.jobs) == 1  # the action is resumed, not restarted
    guard.set_script(FAILURE)
    assert node.tick() is FAILURE
    assert node.message == "region clear failed"
    assert work.job.cancels == 1
    node.reset()
    assert work.job.cancels == 1


def test_reactive_sequence_does_not_restart_finished_actions(ctx: Any) -> None:
    guard = ScriptedLeaf(ctx, "guard", SUCCESS, condition=True)
    first, second = scripted(ctx, (SUCCESS,), (RUNNING, RUNNING, SUCCESS))
    node = with_children(ReactiveSequence(ctx, "rs"), [guard, first, second])
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert (guard.updates, first.updates, second.updates) == (3, 1, 3)


def test_reactive_sequence_rechecks_a_decorated_condition(ctx: Any) -> None:
    person = ScriptedLeaf(ctx, "person in region", FAILURE, condition=True)
    guard = with_children(Inverter(ctx, "no person"), [person])
    action = ScriptedLeaf(ctx, "act", RUNNING)
    node = with_children(ReactiveSequence(ctx, "rs"), [guard, action])
    assert guard.is_condition
    assert [node.tick(), node.tick()] == [RUNNING, RUNNING]
    person.set_script(SUCCESS)
    assert node.tick() is FAILURE
    assert action.halts == 1


def test_reactive_selector_switches_to_a_higher_priority_child(ctx: Any) -> None:
    urgent = ScriptedLeaf(ctx, "part dropped", FAILURE, condition=True)
    work = JobOperation()
    node = with_children(ReactiveSelector(ctx, "rsel"), [urgent, leaf(ctx, work, "tend")])
    assert [node.tick(), node.tick()] == [RUNNING, RUNNING]
    assert urgent.updates == 2 and len(work.jobs) == 1
    urgent.set_script(SUCCESS)
    assert node.tick() is SUCCESS
    assert work.job.cancels == 1
    node.reset()
    assert work.job.cancels == 1


def test_reactive_selector_fails_when_every_option_failed(ctx: Any) -> None:
    cond = ScriptedLeaf(ctx, "c", FAILURE, condition=True)
    action = leaf(ctx, _Fails(), "a", OperationKind.ACTION)
    node = with_children(ReactiveSelector(ctx, "rsel"), [cond, action])
    assert node.tick() is FAILURE
    assert node.message == "every option failed"


class _Fails:
    def start(self, call: Any) -> bool:
        return False


def test_reactive_recheck_reports_only_real_changes() -> None:
    from bt_fakes import recording_ctx

    ctx = recording_ctx()
    guard = ScriptedLeaf(ctx, "guard", SUCCESS, condition=True)
    work = JobOperation()
    node = with_children(ReactiveSequence(ctx, "rs"), [guard, leaf(ctx, work, "move")])
    for _ in range(5):
        assert node.tick() is RUNNING
    assert [c for c in ctx.changes if c[0] == "guard"] == [("guard", IDLE, SUCCESS)]
    guard.set_script(FAILURE)
    assert node.tick() is FAILURE
    assert [c for c in ctx.changes if c[0] == "guard"][-1] == ("guard", SUCCESS, FAILURE)
