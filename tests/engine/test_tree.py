"""The root's run policies, the tree as a whole, and the paper's Figure 3 run until success."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import FakeClock, ScriptedLeaf, logic, op, plan, rooted, with_children

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.composites import Parallel, Sequence
from engine.error_types import ErrorType
from engine.node import Node
from engine.spec import NodeKind, ParameterDecl
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status
from engine.tree import RunPolicy
from engine.types import ParamType, Pose

CUP_AT = Pose((0.4, 0.1, 0.02))
BIN_AT = Pose((0.1, -0.4, 0.0))


def test_once_returns_the_child_result_and_latches(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING, FAILURE)
    tree = rooted(ctx, child)
    assert [tree.tick(), tree.tick(), tree.tick()] == [RUNNING, FAILURE, FAILURE]
    assert child.updates == 2 and tree.root.runs == 1
    assert tree.root.message == "c failed"
    assert ctx.tick_count == 3


def test_until_success_reruns_the_whole_subtree_after_failure(ctx: Any) -> None:
    first = ScriptedLeaf(ctx, "first", SUCCESS)
    flaky = ScriptedLeaf(ctx, "flaky", FAILURE, FAILURE, SUCCESS)
    tree = rooted(ctx, with_children(Sequence(ctx, "seq"), [first, flaky]), RunPolicy.UNTIL_SUCCESS)
    statuses = [tree.tick() for _ in range(5)]
    assert statuses == [RUNNING, RUNNING, SUCCESS, SUCCESS, SUCCESS]
    assert (first.updates, flaky.updates) == (3, 3)  # reset cleared the whole subtree
    assert tree.root.runs == 3
    assert [m for _, m in ctx.logs] == [
        "run 1 ended with FAILURE; starting again",
        "run 2 ended with FAILURE; starting again",
    ]


def test_forever_reruns_after_every_result(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS, FAILURE)
    tree = rooted(ctx, child, RunPolicy.FOREVER)
    assert tree.tick_until_done(max_ticks=10) is RUNNING
    assert child.updates == 10 and tree.root.runs == 10
    tree.reset()
    assert tree.root.runs == 0 and child.status is IDLE


class Failing(Node):
    """A leaf that fails with the next of its messages each time it runs."""

    kind = "action"

    def __init__(self, ctx: Any, name: str, *messages: str) -> None:
        super().__init__(ctx, name, name)
        self.messages = list(messages)
        self.runs = 0

    def update(self) -> Status:
        message = self.messages[min(self.runs, len(self.messages) - 1)]
        self.runs += 1
        return self.fail(message, ErrorType.GRASP_FAILED)


def test_until_success_gives_up_after_5_identical_failures_in_a_row(ctx: Any) -> None:
    grasp = Failing(ctx, "grasp CUP", "nothing between the fingers")
    tree = rooted(ctx, grasp, RunPolicy.UNTIL_SUCCESS)
    assert tree.tick_until_done(max_ticks=100) is FAILURE
    assert grasp.runs == 5 and tree.root.runs == 5
    assert tree.root.message == (
        "stopped after 5 identical failures in a row: "
        "grasp CUP failed (grasp_failed): nothing between the fingers"
    )
    assert tree.root.error is ErrorType.GRASP_FAILED


def test_a_different_failure_starts_the_count_again(ctx: Any) -> None:
    grasp = Failing(ctx, "grasp", "a", "a", "b", "a", "a", "a")  # then "a" for ever
    tree = rooted(ctx, grasp, RunPolicy.UNTIL_SUCCESS)
    tree.root.give_up_after = 3
    assert tree.tick_until_done(max_ticks=100) is FAILURE
    assert grasp.runs == 6  # a a b, then three a in a row


def test_no_limit_and_forever_never_give_up(ctx: Any) -> None:
    for policy, limit in ((RunPolicy.UNTIL_SUCCESS, 0), (RunPolicy.FOREVER, 5)):
        grasp = Failing(ctx, "grasp", "the same")
        tree = rooted(ctx, grasp, policy)
        tree.root.give_up_after = limit
        assert tree.tick_until_done(max_ticks=50) is RUNNING
        assert grasp.runs == 50


def test_the_first_failed_option_of_a_fallback_is_what_counts(
    registry: CapabilityRegistry, clock: FakeClock
) -> None:
    """Figure 3 without a cup: the transfer fails at "CUP found" every time, then the forced
    failure of the wait; the root gives up naming the missing cup, not the wait.
    """
    tree, _ = figure3(registry, clock, failures=100)
    assert run_by_hand(tree, clock) is FAILURE
    assert tree.root.runs == 5
    assert tree.root.message == (
        "stopped after 5 identical failures in a row: OBJECT_FOUND failed: false"
    )
    tree, _ = figure3(registry, clock, failures=6)
    tree.root.give_up_after = 7
    assert run_by_hand(tree, clock, max_ticks=400) is SUCCESS


def test_running_leaves_and_reset(ctx: Any) -> None:
    a, b = ScriptedLeaf(ctx, "a", SUCCESS), ScriptedLeaf(ctx, "b", RUNNING)
    tree = rooted(ctx, with_children(Sequence(ctx, "seq"), [a, b]))
    tree.tick()
    assert tree.running_leaves() == [b]
    assert set(tree.nodes) == {"root", "seq", "a", "b"}
    tree.reset()
    assert b.halts == 1 and tree.status is IDLE
    assert [n.status for n in tree.iterate()] == [IDLE] * 4


# ---------------------------------------------------------------------- Figure 3


def figure3(registry: CapabilityRegistry, clock: FakeClock, failures: int = 2) -> Any:
    """The transfer task of the paper's Figure 3, on the debug capability.

    The cup is "found" after ``failures`` negative checks; until then the selector falls back
    to a wait that is forced to fail, so that the root (until success) runs the tree again.
    """
    transfer = logic(
        NodeKind.SEQUENCE,
        logic(
            NodeKind.PARALLEL,
            op("debug.running", "detect CUP", ticks=1),
            op("debug.running", "detect BIN", ticks=2),
        ),
        op("debug.succeed_after", "OBJECT_FOUND", failures=failures),
        op("debug.query", "query CUP_POSE", value=CUP_AT, result="$CUP_POSE"),
        op("debug.query", "query BIN_POSE", value=BIN_AT, result="$BIN_POSE"),
        op("debug.pretend_move", "MOVE_TO CUP_POSE", target="$CUP_POSE", ticks=1),
        op("debug.succeed", "GRASP"),
        op("debug.pretend_move", "MOVE_TO BIN_POSE", target="$BIN_POSE", ticks=1),
        op("debug.succeed", "RELEASE"),
        name="transfer",
    )
    wait = logic(NodeKind.FORCE_FAILURE, logic(NodeKind.WAIT, name="WAIT", seconds=1.0))
    spec = plan(logic(NodeKind.SELECTOR, transfer, wait), RunPolicy.UNTIL_SUCCESS)
    tree = build_tree(spec, registry, clock=clock)
    changes: list[tuple[str, Status]] = []
    labels = {n.id: n.name for n in tree.iterate()}
    tree.ctx.status_sink = lambda node, old, new: changes.append((labels[node.id], new))
    return tree, changes


def run_by_hand(tree: Any, clock: FakeClock, max_ticks: int = 200) -> Status:
    for _ in range(max_ticks):
        status = tree.tick()
        if status is not RUNNING:
            return status
        clock.advance(0.05)  # 20 Hz
    return RUNNING


def test_figure3_waits_until_the_cup_appears_then_transfers_it(
    registry: CapabilityRegistry, clock: FakeClock
) -> None:
    tree, changes = figure3(registry, clock, failures=2)
    assert run_by_hand(tree, clock) is SUCCESS
    assert tree.root.runs == 3  # two runs without a cup, the third one completes
    waits = [s for label, s in changes if label == "WAIT"]
    assert waits.count(SUCCESS) == 2  # the fallback waited in each failed run
    found = [s for label, s in changes if label == "OBJECT_FOUND"]
    assert [s for s in found if s is not IDLE] == [FAILURE, FAILURE, SUCCESS]
    moves = [label for label, s in changes if s is SUCCESS and label.startswith("MOVE_TO")]
    assert moves == ["MOVE_TO CUP_POSE", "MOVE_TO BIN_POSE"]
    assert tree.blackboard.snapshot() == {"CUP_POSE": CUP_AT, "BIN_POSE": BIN_AT}
    # the wait lasted its second on the tree clock each time: 2 waits of 1 s at 20 Hz
    assert clock.now >= 100.0 + 2 * 1.0


def test_figure3_with_the_cup_present_runs_once(
    registry: CapabilityRegistry, clock: FakeClock
) -> None:
    tree, changes = figure3(registry, clock, failures=0)
    assert run_by_hand(tree, clock) is SUCCESS
    assert tree.root.runs == 1
    assert not [label for label, _ in changes if label == "WAIT"]


def test_figure3_once_fails_when_the_cup_is_missing(
    registry: CapabilityRegistry, clock: FakeClock
) -> None:
    tree, _ = figure3(registry, clock, failures=2)
    tree.root.policy = RunPolicy.ONCE
    assert run_by_hand(tree, clock) is FAILURE
    assert tree.root.message == "every option failed"


def test_each_tree_has_its_own_blackboard(registry: CapabilityRegistry) -> None:
    spec = plan(
        op("debug.set_param", value=7, name="$COUNT"),
        parameters=[
            ParameterDecl("COUNT", ParamType.NUMBER, 1),
            ParameterDecl("NAME", ParamType.TEXT),
        ],
    )
    one, two = build_tree(spec, registry), build_tree(spec, registry)
    assert one.blackboard is not two.blackboard
    assert one.ctx is not two.ctx
    assert one.tick() is SUCCESS
    assert one.blackboard.get("COUNT") == 7
    assert two.blackboard.get("COUNT") == 1
    assert two.blackboard.type_of("NAME") is ParamType.TEXT


def test_tree_reset_halts_a_running_node_under_a_parent_that_never_returned(ctx: Any) -> None:
    class Broken(ScriptedLeaf):
        def update(self) -> Status:
            raise RuntimeError("bug")

    busy = ScriptedLeaf(ctx, "busy", RUNNING)
    tree = rooted(ctx, with_children(Parallel(ctx, "par"), [busy, Broken(ctx, "x")]))
    with pytest.raises(RuntimeError):
        tree.tick()
    assert (tree.root.status, busy.status) == (IDLE, RUNNING)  # the tick was cut short
    tree.reset()
    assert busy.halts == 1 and busy.status is IDLE
    tree.reset()
    assert busy.halts == 1
