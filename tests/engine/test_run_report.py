"""FailureLog: the failures a run carried on past, and the node that caught each."""

from __future__ import annotations

from typing import Any

from bt_fakes import logic, op, plan

from capabilities.base import CapabilityRegistry
from engine.build import ROOT_ID, build_tree
from engine.events import StatusChanged
from engine.failure_words import failed_words, node_title
from engine.run_report import FailureLog, RootCause
from engine.spec import NodeKind, NodeSpec, PlanSpec, SubtreeSpec
from engine.status import FAILURE, Status
from engine.tree import RunPolicy


def changed(tick: int, node_id: str, new: Status, message: str = "") -> StatusChanged:
    return StatusChanged(tick, node_id, Status.RUNNING, new, message, 0.0)


def test_a_failure_a_selector_recovers_from_names_the_selector() -> None:
    move = op("debug.fail", "move to CUP_POSE")
    other = op("debug.succeed", "other way")
    selector = logic(NodeKind.SELECTOR, move, other, name="transfer or wait")
    log = FailureLog(plan(selector))
    for event in (
        changed(3, move.id, Status.FAILURE, "collision with the table"),
        changed(4, other.id, Status.SUCCESS),
        changed(4, selector.id, Status.SUCCESS),
        changed(4, ROOT_ID, Status.SUCCESS),
    ):
        log(event)
    (caught,) = log.on_the_way()
    assert caught.describe() == (
        "move to CUP_POSE failed: collision with the table; caught by Selector 'transfer or wait'"
    )


def test_a_failure_that_travels_up_is_named_once_with_the_node_that_stopped_it() -> None:
    check = op("debug.condition", "CUP found")
    step = logic(NodeKind.SEQUENCE, check, name="transfer")
    top = logic(NodeKind.SELECTOR, step, name="try")
    log = FailureLog(plan(top, RunPolicy.UNTIL_SUCCESS))
    for tick in (2, 5):  # twice: the condition, its sequence and the selector fail together
        for node in (check, step, top):
            log(changed(tick, node.id, Status.FAILURE, "false"))
    log(changed(8, check.id, Status.SUCCESS))
    log(changed(8, step.id, Status.SUCCESS))
    log(changed(8, top.id, Status.SUCCESS))
    log(changed(8, ROOT_ID, Status.SUCCESS))
    (caught,) = log.on_the_way()
    assert caught.node == "CUP found" and caught.times == 2 and caught.message == "false"
    assert caught.caught_by == "the plan's root (runs until success)"


def test_a_failure_that_ends_the_run_is_not_caught() -> None:
    move = op("debug.fail", "move")
    sequence = logic(NodeKind.SEQUENCE, move, name="all")
    log = FailureLog(plan(sequence))
    log(changed(1, move.id, Status.FAILURE, "no"))
    log(changed(1, sequence.id, Status.FAILURE, "no"))
    log(changed(1, ROOT_ID, Status.FAILURE, "no"))
    assert log.on_the_way() == []
    assert log.cause() == "move failed: no; passed up by Sequence 'all'"


# ---------------------------------------------------------------------- real runs


def run_logged(spec: PlanSpec, registry: CapabilityRegistry) -> tuple[Status, str, FailureLog]:
    """Run the plan to its end, its events into a FailureLog as the executor makes them."""
    tree = build_tree(spec, registry)
    log = FailureLog(spec)
    ctx = tree.ctx

    def sink(node: Any, old: Status, new: Status) -> None:
        error = node.error.value if new is FAILURE and node.error is not None else ""
        log(StatusChanged(ctx.tick_count, node.id, old, new, node.message, 0.0, error))

    ctx.status_sink = sink
    status = tree.tick_until_done(max_ticks=1000)
    return status, tree.root.message, log


def pick_behind_a_retry_and_a_fallback(fallback: NodeSpec) -> NodeSpec:
    pick = op(
        "debug.fail", "grasp CUP", message="nothing between the fingers", error="grasp_failed"
    )
    retry = logic(NodeKind.RETRY, pick, name="pick 4 times", count=4)
    return logic(NodeKind.SELECTOR, retry, fallback, name="pick or ask")


def test_a_leaf_failing_4_times_behind_a_retry_and_a_fallback_is_counted_once(
    registry: CapabilityRegistry,
) -> None:
    ask = op("debug.succeed", "ask for help")
    status, _, log = run_logged(plan(pick_behind_a_retry_and_a_fallback(ask)), registry)
    assert status is Status.SUCCESS and log.cause() == "" and log.failed_run() is None
    (pick,) = log.on_the_way()
    assert (pick.node, pick.message, pick.error, pick.times) == (
        "grasp CUP",
        "nothing between the fingers",
        "grasp_failed",
        4,
    )
    assert pick.describe() == (
        "grasp CUP failed 4 times (grasp_failed): nothing between the fingers; "
        "passed up by Retry 'pick 4 times'; caught by Selector 'pick or ask'"
    )


def test_a_run_that_fails_names_the_first_leaf_not_the_fallback_that_failed_after_it(
    registry: CapabilityRegistry,
) -> None:
    ask = op("debug.fail", "ask for help", message="no one answered")
    status, _, log = run_logged(plan(pick_behind_a_retry_and_a_fallback(ask)), registry)
    assert status is Status.FAILURE
    assert log.cause() == (
        "grasp CUP failed 4 times (grasp_failed): nothing between the fingers; "
        "passed up by Retry 'pick 4 times', Selector 'pick or ask'"
    )
    (other,) = log.on_the_way()
    assert (
        other.describe()
        == "ask for help failed: no one answered; passed up by Selector 'pick or ask'"
    )


def test_until_success_gives_up_and_the_cause_says_so_with_every_attempt_counted(
    registry: CapabilityRegistry,
) -> None:
    ask = op("debug.fail", "ask for help", message="no one answered")
    spec = plan(pick_behind_a_retry_and_a_fallback(ask), RunPolicy.UNTIL_SUCCESS)
    spec.give_up_after = 3
    status, message, log = run_logged(spec, registry)
    assert status is Status.FAILURE
    assert message == (
        "stopped after 3 identical failures in a row: "
        "grasp CUP failed (grasp_failed): nothing between the fingers"
    )
    cause = log.failed_run()
    assert cause is not None and cause.times == 12 and cause.stopped_after == 3
    assert log.cause().startswith(
        "stopped after 3 identical failures in a row: grasp CUP failed 12 times (grasp_failed)"
    )
    assert RootCause.from_record(cause.as_record()) == cause


def test_a_failure_inside_an_instance_is_named_with_the_instance(
    registry: CapabilityRegistry,
) -> None:
    grasp = op("debug.fail", "grasp CUP", message="nothing between the fingers")
    inner = logic(NodeKind.SEQUENCE, grasp, name="Pick")
    sub = SubtreeSpec(id="test.pick", name="Pick", tree=inner, version=1)
    pick = NodeSpec(NodeKind.SUBTREE, name="Pick cup", subtree=sub.ref)
    top = logic(NodeKind.SEQUENCE, pick, name="transfer")
    status, _, log = run_logged(plan(top, subtrees=[sub]), registry)
    assert status is Status.FAILURE
    cause = log.failed_run()
    assert cause is not None and cause.node_id == f"{pick.id}/{grasp.id}"
    assert cause.describe() == (
        "Pick cup > grasp CUP failed: nothing between the fingers; passed up by "
        "Pick cup > Sequence 'Pick', Pick cup, Sequence 'transfer'"
    )


def test_how_nodes_and_failures_are_put_in_words() -> None:
    assert node_title("selector", "Selector", leaf=False) == "Selector"
    assert node_title("force_failure", "force_failure", leaf=False) == "Force failure"
    assert node_title("retry", "pick 4 times", leaf=False) == "Retry 'pick 4 times'"
    assert node_title("action", "grasp CUP", leaf=True) == "grasp CUP"
    assert failed_words("grasp CUP", "failed", "nothing between the fingers", 3) == (
        "grasp CUP failed 3 times: nothing between the fingers"
    )
    assert failed_words("look", "not_found", "") == "look failed (not_found)"
