"""FailureLog: the failures a run carried on past, and the node that caught each."""

from __future__ import annotations

from bt_fakes import logic, op, plan

from engine.build import ROOT_ID
from engine.events import StatusChanged
from engine.run_report import FailureLog
from engine.spec import NodeKind
from engine.status import Status
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
    (caught,) = log.caught()
    assert caught.describe() == (
        "move to CUP_POSE failed (collision with the table), caught by Selector 'transfer or wait'"
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
    (caught,) = log.caught()
    assert caught.node == "CUP found" and caught.times == 2 and caught.message == "false"
    assert caught.caught_by == "the plan's root (runs until success)"


def test_a_failure_that_ends_the_run_is_not_caught() -> None:
    move = op("debug.fail", "move")
    sequence = logic(NodeKind.SEQUENCE, move, name="all")
    log = FailureLog(plan(sequence))
    log(changed(1, move.id, Status.FAILURE, "no"))
    log(changed(1, sequence.id, Status.FAILURE, "no"))
    log(changed(1, ROOT_ID, Status.FAILURE, "no"))
    assert log.caught() == []
