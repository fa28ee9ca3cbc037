"""The Catch node: body, handler, caught and uncaught error types, halting and latching."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import FuncOperation, JobOperation, ScriptedLeaf, logic, op, plan, with_children

from capabilities.base import CapabilityRegistry
from engine.btcpp import export_xml, import_xml
from engine.build import build_tree
from engine.catch import Catch
from engine.error_types import ErrorType
from engine.files import dump_plan, loads_plan
from engine.leaves import OperationLeaf
from engine.operations import Job, OperationKind
from engine.spec import NodeKind
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS
from engine.validation import validate_plan


def thrower(ctx: Any, error: ErrorType, name: str = "body") -> OperationLeaf:
    failing = FuncOperation(lambda call: Job.failed(f"{name} went wrong", error))
    return OperationLeaf(ctx, name, name, OperationKind.ACTION, failing)


def catch(ctx: Any, body: Any, handler: Any, errors: Any = None, key: str = "ERR") -> Catch:
    return with_children(Catch(ctx, "catch", "catch", errors, key), [body, handler])  # type: ignore[return-value]


def test_a_body_that_succeeds_never_runs_the_handler(ctx: Any) -> None:
    handler = ScriptedLeaf(ctx, "handler")
    node = catch(ctx, ScriptedLeaf(ctx, "body", RUNNING, SUCCESS), handler)
    assert [node.tick(), node.tick()] == [RUNNING, SUCCESS]
    assert handler.updates == 0 and "ERR" not in ctx.blackboard


def test_a_caught_failure_runs_the_handler_and_keeps_the_error(ctx: Any) -> None:
    handler = ScriptedLeaf(ctx, "handler", RUNNING, SUCCESS)
    body = thrower(ctx, ErrorType.GRASP_FAILED)
    node = catch(ctx, body, handler, {ErrorType.GRASP_FAILED, ErrorType.NOT_FOUND})
    assert node.tick() is RUNNING
    assert ctx.blackboard.get("ERR") == "grasp_failed: body went wrong"
    assert ("catch", "caught grasp_failed: body went wrong") in ctx.logs
    assert node.tick() is SUCCESS and handler.updates == 2
    assert body.status is FAILURE and body.error is ErrorType.GRASP_FAILED  # shown as it was


def test_a_handler_that_fails_fails_the_catch_with_its_type(ctx: Any) -> None:
    handler = thrower(ctx, ErrorType.PROTECTIVE_STOP, "handler")
    node = catch(ctx, thrower(ctx, ErrorType.OBJECT_LOST), handler)  # any
    assert node.tick() is FAILURE
    assert node.error is ErrorType.PROTECTIVE_STOP and node.message == "handler went wrong"


def test_an_uncaught_type_passes_up_to_an_outer_catch(ctx: Any) -> None:
    inner_handler = ScriptedLeaf(ctx, "inner handler")
    inner = Catch(ctx, "inner", "inner", {ErrorType.GRASP_FAILED}, "")
    inner.set_children([thrower(ctx, ErrorType.COLLISION), inner_handler])
    outer_handler = ScriptedLeaf(ctx, "outer handler")
    outer = Catch(ctx, "outer", "outer", {ErrorType.COLLISION}, "WHY")
    outer.set_children([with_children(_seq(ctx), [inner]), outer_handler])
    assert outer.tick() is SUCCESS
    assert inner.status is FAILURE and inner.error is ErrorType.COLLISION
    assert inner.message == "body went wrong" and inner_handler.updates == 0
    assert outer_handler.updates == 1 and ctx.blackboard.get("WHY").startswith("collision:")


def _seq(ctx: Any) -> Any:
    from engine.composites import Sequence

    return Sequence(ctx, "seq", "seq")


def test_halting_while_the_handler_runs_cancels_it_and_reset_starts_over(ctx: Any) -> None:
    work = JobOperation()
    handler = OperationLeaf(ctx, "handler", "handler", OperationKind.ACTION, work)
    body = ScriptedLeaf(ctx, "body", FAILURE)
    node = catch(ctx, body, handler)
    assert node.tick() is RUNNING and len(work.jobs) == 1
    node.reset()
    assert work.job.cancels == 1 and node.status is IDLE and body.status is IDLE
    body.set_script(SUCCESS)
    assert node.tick() is SUCCESS and len(work.jobs) == 1  # the body again, not the handler


def test_a_finished_catch_is_latched(ctx: Any) -> None:
    handler = ScriptedLeaf(ctx, "handler")
    body = ScriptedLeaf(ctx, "body", FAILURE)
    node = catch(ctx, body, handler)
    assert node.tick() is SUCCESS and node.tick() is SUCCESS
    assert (body.updates, handler.updates) == (1, 1)


def test_a_catch_needs_two_children(ctx: Any) -> None:
    with pytest.raises(ValueError, match="needs two children"):
        Catch(ctx, "c", "c").set_children([ScriptedLeaf(ctx, "only")])


def _catch_plan(errors: str = "not_found, timeout", handler_reads: bool = True) -> Any:
    body = op("debug.fail", error="not_found", message="no cup")
    handler = op("debug.log", message="$CAUGHT") if handler_reads else op("debug.succeed")
    return plan(logic(NodeKind.CATCH, body, handler, errors=errors, error="CAUGHT"))


def test_a_plan_with_a_catch_builds_validates_and_runs(registry: CapabilityRegistry) -> None:
    spec = _catch_plan()
    problems = validate_plan(spec, registry)
    assert problems == []  # the handler may read the caught error: no warning
    tree = build_tree(spec, registry)
    status = tree.tick()
    while status is RUNNING:
        status = tree.tick()
    assert status is SUCCESS
    assert tree.ctx.blackboard.get("CAUGHT") == "not_found: no cup"


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        (_catch_plan("not_found, dropped"), "unknown error type 'dropped'"),
        (plan(logic(NodeKind.CATCH, op("debug.succeed"))), "needs two nodes below it"),
    ],
)
def test_validation_names_a_bad_catch(
    registry: CapabilityRegistry, spec: Any, expected: str
) -> None:
    problems = validate_plan(spec, registry)
    assert any(expected in p.message for p in problems), problems


def test_a_catch_round_trips_through_the_plan_file_and_behaviortree_cpp_xml() -> None:
    spec = loads_plan(dump_plan(_catch_plan()))
    text = export_xml(spec, {})
    assert '<Catch ID="Catch"' not in text and "<Catch " in text
    assert '<Control ID="Catch">' in text  # declared: BehaviorTree.CPP has no Catch
    assert import_xml(text, "plan.xml") == spec
