"""Decorators: result mappers, the paper's Iterator and Enforce, Repeat, Retry, Timeout."""

from __future__ import annotations

from typing import Any, TypeVar

import pytest
from bt_fakes import FakeClock, JobOperation, ScriptedLeaf, leaf, with_children

from engine.composites import Sequence
from engine.decorators import (
    Enforce,
    ForceFailure,
    ForceSuccess,
    Inverter,
    Iterator,
    Repeat,
    Retry,
    Timeout,
)
from engine.node import Node
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status

N = TypeVar("N", bound=Node)


def deco(node: N, child: Node) -> N:
    node.set_children([child])
    return node


# ---------------------------------------------------------------------- result mappers


@pytest.mark.parametrize(
    ("cls", "child_status", "expected"),
    [
        (Inverter, SUCCESS, FAILURE),
        (Inverter, FAILURE, SUCCESS),
        (Inverter, RUNNING, RUNNING),
        (ForceSuccess, SUCCESS, SUCCESS),
        (ForceSuccess, FAILURE, SUCCESS),
        (ForceSuccess, RUNNING, RUNNING),
        (ForceFailure, SUCCESS, FAILURE),
        (ForceFailure, FAILURE, FAILURE),
        (ForceFailure, RUNNING, RUNNING),
    ],
)
def test_result_mappers(ctx: Any, cls: type[Node], child_status: Status, expected: Status) -> None:
    node = deco(cls(ctx, "d"), ScriptedLeaf(ctx, "c", child_status))
    assert node.tick() is expected


def test_a_decorator_of_a_condition_is_a_condition_only_when_it_maps_results(ctx: Any) -> None:
    cond = ScriptedLeaf(ctx, "c", condition=True)
    assert deco(Inverter(ctx, "i"), cond).is_condition
    assert not deco(Inverter(ctx, "i2"), ScriptedLeaf(ctx, "a")).is_condition
    assert not deco(Retry(ctx, "r", count=2), ScriptedLeaf(ctx, "c2", condition=True)).is_condition


@pytest.mark.parametrize("n", [0, 2])
def test_a_decorator_needs_exactly_one_child(ctx: Any, n: int) -> None:
    with pytest.raises(ValueError, match="needs exactly one child"):
        Inverter(ctx, "i").set_children([ScriptedLeaf(ctx, f"c{i}") for i in range(n)])


# ---------------------------------------------------------------------- Iterator


def test_iterator_resets_its_child_on_success_until_the_count(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS)
    node = deco(Iterator(ctx, "it", count=3), child)
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert child.updates == 3  # one round per tick: a child that succeeds at once cannot spin
    assert child.resets == 2 and node.done == 3


def test_iterator_resets_the_whole_subtree_of_its_child(ctx: Any) -> None:
    first, second = ScriptedLeaf(ctx, "first", SUCCESS), ScriptedLeaf(ctx, "second", SUCCESS)
    node = deco(Iterator(ctx, "it", count=2), with_children(Sequence(ctx, "seq"), [first, second]))
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]
    assert (first.updates, second.updates) == (2, 2)


def test_iterator_passes_failure(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS, SUCCESS, FAILURE)
    node = deco(Iterator(ctx, "it"), child)
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, FAILURE]
    assert node.tick() is FAILURE and child.updates == 3  # latched


def test_iterator_timeout_succeeds_and_halts_the_running_child(ctx: Any, clock: FakeClock) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS, RUNNING)
    node = deco(Iterator(ctx, "it", timeout=5.0), child)
    assert node.tick() is RUNNING
    clock.advance(4.9)
    assert node.tick() is RUNNING
    clock.advance(0.1)
    assert node.tick() is SUCCESS
    assert child.halts == 1 and child.status is IDLE
    assert node.message == "time limit of 5 s reached after 1 rounds"


def test_iterator_clock_starts_again_after_reset(ctx: Any, clock: FakeClock) -> None:
    node = deco(Iterator(ctx, "it", timeout=1.0), ScriptedLeaf(ctx, "c", RUNNING))
    node.tick()
    clock.advance(10.0)
    node.reset()
    assert node.tick() is RUNNING  # the timer starts at the first tick after the reset
    assert node.done == 0


# ---------------------------------------------------------------------- Enforce


def test_enforce_retries_until_success(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", FAILURE, FAILURE, SUCCESS)
    node = deco(Enforce(ctx, "en"), child)
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert child.resets == 2


def test_enforce_resets_the_whole_subtree(ctx: Any) -> None:
    first = ScriptedLeaf(ctx, "first", SUCCESS)
    flaky = ScriptedLeaf(ctx, "flaky", FAILURE, SUCCESS)
    node = deco(Enforce(ctx, "en"), with_children(Sequence(ctx, "seq"), [first, flaky]))
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]
    assert first.updates == 2  # the succeeded sibling ran again after the reset


def test_enforce_count_gives_up_with_failure(ctx: Any) -> None:
    node = deco(Enforce(ctx, "en", count=2), ScriptedLeaf(ctx, "c", FAILURE))
    assert [node.tick(), node.tick()] == [RUNNING, FAILURE]
    assert node.message == "failed 2 times"


def test_enforce_timeout_fails_and_halts_the_running_child(ctx: Any, clock: FakeClock) -> None:
    child = ScriptedLeaf(ctx, "c", FAILURE, RUNNING)
    node = deco(Enforce(ctx, "en", timeout=2.0), child)
    assert node.tick() is RUNNING
    clock.advance(2.0)
    assert node.tick() is FAILURE
    assert child.halts == 1
    assert "time limit of 2 s" in node.message


@pytest.mark.parametrize(
    ("kwargs", "match"), [({"count": 0}, "count"), ({"timeout": 0.0}, "timeout")]
)
def test_looping_decorators_refuse_bad_settings(
    ctx: Any, kwargs: dict[str, Any], match: str
) -> None:
    with pytest.raises(ValueError, match=match):
        Iterator(ctx, "it", **kwargs)
    with pytest.raises(ValueError, match=match):
        Enforce(ctx, "en", **kwargs)


# ---------------------------------------------------------------------- Repeat, Retry


def test_repeat_runs_the_child_n_times(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING, SUCCESS)
    node = deco(Repeat(ctx, "rep", count=2), child)
    child.script = [RUNNING, SUCCESS, RUNNING, SUCCESS]
    # BehaviorTree.CPP's Repeat: a child that finished after running starts again in the
    # same tick
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert child.updates == 4


def test_repeat_gives_the_tick_back_after_a_child_that_succeeded_at_once(ctx: Any) -> None:
    node = deco(Repeat(ctx, "rep", count=3), ScriptedLeaf(ctx, "c", SUCCESS))
    wakes: list[int] = []
    ctx.wake = lambda: wakes.append(1)
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, SUCCESS]
    assert len(wakes) == 2


def test_repeat_stops_at_a_failure(ctx: Any) -> None:
    node = deco(Repeat(ctx, "rep", count=5), ScriptedLeaf(ctx, "c", SUCCESS, FAILURE))
    assert [node.tick(), node.tick()] == [RUNNING, FAILURE]


def test_retry_tries_n_times(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", FAILURE)
    node = deco(Retry(ctx, "retry", count=3), child)
    assert [node.tick() for _ in range(3)] == [RUNNING, RUNNING, FAILURE]
    assert child.updates == 3 and node.message == "failed 3 times"


def test_retry_succeeds_at_the_first_success(ctx: Any) -> None:
    node = deco(Retry(ctx, "retry", count=3), ScriptedLeaf(ctx, "c", FAILURE, SUCCESS))
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]


def test_repeat_and_retry_with_a_count_of_minus_1_have_no_limit(ctx: Any) -> None:
    # BehaviorTree.CPP's num_cycles="-1" and num_attempts="-1"
    repeat = deco(Repeat(ctx, "rep", count=-1), ScriptedLeaf(ctx, "c", SUCCESS))
    assert {repeat.tick() for _ in range(20)} == {RUNNING}
    child = ScriptedLeaf(ctx, "d", *[FAILURE] * 20, SUCCESS)
    retry = deco(Retry(ctx, "retry", count=-1), child)
    assert [retry.tick() for _ in range(21)] == [RUNNING] * 20 + [SUCCESS]


# ---------------------------------------------------------------------- Timeout


def test_timeout_halts_its_child_and_fails(ctx: Any, clock: FakeClock) -> None:
    work = JobOperation()
    node = deco(Timeout(ctx, "to", seconds=2.0), leaf(ctx, work, "move"))
    assert node.tick() is RUNNING
    clock.advance(1.5)
    assert node.tick() is RUNNING
    clock.advance(0.5)
    assert node.tick() is FAILURE
    assert node.message == "timed out after 2 s"
    assert work.job.cancels == 1
    node.reset()
    assert work.job.cancels == 1


def test_timeout_passes_a_result_within_time(ctx: Any, clock: FakeClock) -> None:
    node = deco(Timeout(ctx, "to", seconds=2.0), ScriptedLeaf(ctx, "c", RUNNING, FAILURE))
    node.tick()
    clock.advance(1.0)
    assert node.tick() is FAILURE
    assert node.message == ""


def test_timeout_timer_restarts_after_reset(ctx: Any, clock: FakeClock) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING)
    node = deco(Timeout(ctx, "to", seconds=1.0), child)
    node.tick()
    clock.advance(0.9)
    node.reset()
    clock.advance(0.9)
    assert node.tick() is RUNNING
    assert child.status is RUNNING and node.status is not IDLE


def test_timeout_refuses_a_non_positive_limit(ctx: Any) -> None:
    with pytest.raises(ValueError, match="above 0"):
        Timeout(ctx, "to", seconds=0)
