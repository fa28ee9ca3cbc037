"""The debug capability: each operation does what its doc says."""

from __future__ import annotations

from typing import Any

import pytest

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.debug import capability
from engine.build import build_tree
from engine.composites import Sequence
from engine.operations import OperationKind
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, RUNNING, SUCCESS, Status
from engine.tree import BehaviorTree
from engine.types import ParamType, Pose
from engine.validation import validate_plan


@pytest.fixture
def registry() -> CapabilityRegistry:
    return CapabilityRegistry([capability()])


def node(op_id: str, **params: Any) -> NodeSpec:
    """An operation node; a str starting with '$' is a reference."""
    bindings = {
        port: Binding.reference(value[1:])
        if isinstance(value, str) and value.startswith("$")
        else Binding(value=value, type=ParamType.ANY)
        for port, value in params.items()
    }
    return NodeSpec(NodeKind.OPERATION, op=op_id, params=bindings)


def tree_of(registry: CapabilityRegistry, *nodes: NodeSpec) -> BehaviorTree:
    top = nodes[0] if len(nodes) == 1 else NodeSpec(NodeKind.SEQUENCE, children=list(nodes))
    return build_tree(PlanSpec(tree=top), registry)


def ticks(tree: BehaviorTree, limit: int = 20) -> list[Status]:
    out = [tree.tick()]
    while out[-1] is RUNNING and len(out) < limit:
        out.append(tree.tick())
    return out


def only_leaf(tree: BehaviorTree) -> Any:
    return tree.root.children[0]


def test_every_operation_is_documented_and_always_available(registry: CapabilityRegistry) -> None:
    kinds = {m.id: m.kind for m in registry.manifests()}
    assert kinds == {
        "debug.succeed": OperationKind.ACTION,
        "debug.fail": OperationKind.ACTION,
        "debug.running": OperationKind.ACTION,
        "debug.pretend_move": OperationKind.ACTION,
        "debug.set_param": OperationKind.ACTION,
        "debug.query": OperationKind.QUERY,
        "debug.check_param": OperationKind.CONDITION,
        "debug.condition": OperationKind.CONDITION,
        "debug.succeed_after": OperationKind.CONDITION,
        "debug.log": OperationKind.ACTION,
    }
    for manifest in registry.manifests():
        assert manifest.doc and manifest.capability == "debug"
        assert all(port.doc for port in manifest.ports), manifest.id
        assert registry.availability(manifest.id).available
    assert isinstance(registry.cell, NullCell)


def test_succeed(registry: CapabilityRegistry) -> None:
    assert ticks(tree_of(registry, node("debug.succeed"))) == [SUCCESS]


@pytest.mark.parametrize(
    ("params", "message"), [({}, "failed on purpose"), ({"message": "no cup"}, "no cup")]
)
def test_fail(registry: CapabilityRegistry, params: dict[str, Any], message: str) -> None:
    tree = tree_of(registry, node("debug.fail", **params))
    assert ticks(tree) == [FAILURE]
    assert only_leaf(tree).message == message


def test_running_for_n_ticks_then_success(registry: CapabilityRegistry) -> None:
    assert ticks(tree_of(registry, node("debug.running", ticks=2))) == [RUNNING, RUNNING, SUCCESS]
    assert ticks(tree_of(registry, node("debug.running", ticks=0))) == [SUCCESS]


def test_running_then_failure_with_a_message(registry: CapabilityRegistry) -> None:
    tree = tree_of(registry, node("debug.running", ticks=1, then="FAILURE", message="jammed"))
    assert ticks(tree) == [RUNNING, FAILURE]
    assert only_leaf(tree).message == "jammed"
    tree = tree_of(registry, node("debug.running", ticks=0, then="FAILURE"))
    assert ticks(tree) == [FAILURE] and only_leaf(tree).message == "failed on purpose"


def test_running_ends_a_success_with_its_message_too(registry: CapabilityRegistry) -> None:
    # issue 26: no input accepted and then ignored (the message was read only on FAILURE)
    tree = tree_of(registry, node("debug.running", ticks=0, message="parked"))
    assert ticks(tree) == [SUCCESS] and only_leaf(tree).message == "parked"


def test_running_refuses_a_negative_count(registry: CapabilityRegistry) -> None:
    tree = tree_of(registry, node("debug.running", ticks=-1))
    assert ticks(tree) == [FAILURE]
    assert only_leaf(tree).message.startswith("ticks must be 0 or more")


def test_a_value_outside_the_choices_is_a_validation_error(registry: CapabilityRegistry) -> None:
    spec = NodeSpec(NodeKind.OPERATION, op="debug.running",
                    params={"then": Binding.fixed("MAYBE", ParamType.TEXT)})  # fmt: skip
    plan = PlanSpec(spec, "t")
    messages = [p.message for p in validate_plan(plan, registry)]
    assert any("must be one of SUCCESS, FAILURE, not 'MAYBE'" in m for m in messages), messages


def test_pretend_move_logs_and_runs(registry: CapabilityRegistry) -> None:
    target = Pose((0.3, 0.0, 0.2))
    tree = tree_of(registry, node("debug.pretend_move", target=target, ticks=1))
    logs: list[tuple[str, str]] = []
    tree.ctx.log_sink = lambda node_id, message: logs.append((node_id, message))
    assert ticks(tree) == [RUNNING, SUCCESS]
    assert logs == [(only_leaf(tree).id, f"moving to {target}")]


def test_set_param_writes_the_named_parameter(registry: CapabilityRegistry) -> None:
    tree = tree_of(registry, node("debug.set_param", value="CUP", name="$OBJECT"))
    assert ticks(tree) == [SUCCESS]
    assert tree.blackboard.get("OBJECT") == "CUP"


def test_query_answers_with_its_value(registry: CapabilityRegistry) -> None:
    pose = Pose((0.5, 0.1, 0.0))
    tree = tree_of(registry, node("debug.query", value=pose, result="$CUP_POSE"))
    assert ticks(tree) == [SUCCESS]
    assert tree.blackboard.get("CUP_POSE") == pose


@pytest.mark.parametrize(("value", "expected"), [(3, SUCCESS), (4, FAILURE)])
def test_check_param_compares_a_parameter(
    registry: CapabilityRegistry, value: int, expected: Status
) -> None:
    tree = tree_of(
        registry,
        node("debug.set_param", value=value, name="$N"),
        node("debug.check_param", value="$N", expected=3),
    )
    assert ticks(tree) == [expected]


@pytest.mark.parametrize(
    ("params", "expected"),
    [({}, SUCCESS), ({"result": True}, SUCCESS), ({"result": False}, FAILURE)],
)
def test_condition_answers_as_set(
    registry: CapabilityRegistry, params: dict[str, Any], expected: Status
) -> None:
    tree = tree_of(registry, node("debug.condition", **params))
    assert ticks(tree) == [expected]
    assert only_leaf(tree).is_condition


def test_succeed_after_is_false_n_times_per_leaf(registry: CapabilityRegistry) -> None:
    tree = tree_of(
        registry, node("debug.succeed_after", failures=2), node("debug.succeed_after", failures=1)
    )
    first, second = tree.root.children[0].children
    answers = []
    for _ in range(3):
        first.reset()
        answers.append(first.tick())
    assert answers == [FAILURE, FAILURE, SUCCESS]  # the count survives resets of the leaf
    assert second.tick() is FAILURE  # its own count
    second.reset()
    assert second.tick() is SUCCESS
    assert isinstance(tree.root.children[0], Sequence)


def test_log_writes_to_the_run_log(registry: CapabilityRegistry) -> None:
    tree = tree_of(registry, node("debug.log", message="start of shift"))
    logs: list[str] = []
    tree.ctx.log_sink = lambda node_id, message: logs.append(message)
    assert ticks(tree) == [SUCCESS]
    assert logs == ["start of shift"]
