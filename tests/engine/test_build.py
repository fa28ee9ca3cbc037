"""Spec + registry -> runnable tree: node kinds, settings, bindings and build errors."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import FakeClock, logic, op, plan

from capabilities.base import Capability, CapabilityEnv, CapabilityRegistry
from engine.blackboard import Blackboard
from engine.build import ROOT_ID, BuildError, build_tree
from engine.composites import (
    Parallel,
    ReactiveSelector,
    ReactiveSequence,
    Selector,
    Sequence,
)
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
from engine.errors import EngineError
from engine.leaves import OperationLeaf, Wait
from engine.operations import (
    Direction,
    Job,
    OperationCall,
    OperationKind,
    OperationManifest,
    PortSpec,
)
from engine.spec import NodeKind, ParameterDecl, PlanSpec
from engine.status import RUNNING, SUCCESS
from engine.tree import Root, RunPolicy
from engine.types import ParamType

LEAF = op("debug.succeed")

KIND_CLASS = [
    (NodeKind.SEQUENCE, Sequence, {}),
    (NodeKind.SELECTOR, Selector, {}),
    (NodeKind.PARALLEL, Parallel, {}),
    (NodeKind.REACTIVE_SEQUENCE, ReactiveSequence, {}),
    (NodeKind.REACTIVE_SELECTOR, ReactiveSelector, {}),
    (NodeKind.ITERATOR, Iterator, {}),
    (NodeKind.ENFORCE, Enforce, {}),
    (NodeKind.INVERTER, Inverter, {}),
    (NodeKind.REPEAT, Repeat, {"count": 2}),
    (NodeKind.RETRY, Retry, {"count": 2}),
    (NodeKind.TIMEOUT, Timeout, {"seconds": 1.5}),
    (NodeKind.FORCE_SUCCESS, ForceSuccess, {}),
    (NodeKind.FORCE_FAILURE, ForceFailure, {}),
]


@pytest.mark.parametrize(("kind", "cls", "config"), KIND_CLASS)
def test_every_logic_kind_builds_its_node(
    registry: CapabilityRegistry, kind: NodeKind, cls: type, config: dict[str, Any]
) -> None:
    spec = logic(kind, LEAF, name="the node", **config)
    tree = build_tree(plan(spec), registry)
    node = tree.nodes[spec.id]
    assert type(node) is cls
    assert node.name == "the node"
    assert [c.id for c in node.children] == [LEAF.id]
    assert node.children[0].parent is node


def test_settings_and_defaults_reach_the_nodes(registry: CapabilityRegistry) -> None:
    par = logic(NodeKind.PARALLEL, LEAF)
    par_m = logic(NodeKind.PARALLEL, op("debug.succeed"), success=1, failure=2)
    it = logic(NodeKind.ITERATOR, op("debug.succeed"), count=3, timeout=2.5)
    rep = logic(NodeKind.REPEAT, op("debug.succeed"), count=4)
    to = logic(NodeKind.TIMEOUT, op("debug.succeed"), seconds=3)
    wait = logic(NodeKind.WAIT, seconds=0.5)
    tree = build_tree(plan(logic(NodeKind.SEQUENCE, par, par_m, it, rep, to, wait)), registry)
    n: dict[str, Any] = tree.nodes
    assert (n[par.id].policy.success, n[par.id].policy.failure) == ("all", "any")
    assert (n[par_m.id].policy.success, n[par_m.id].policy.failure) == (1, 2)
    assert (n[it.id].count, n[it.id].timeout) == (3, 2.5)
    assert n[rep.id].count == 4
    assert n[to.id].seconds == 3.0
    assert isinstance(n[wait.id], Wait) and n[wait.id].seconds == 0.5


def test_root_carries_the_plan_name_and_policy(registry: CapabilityRegistry) -> None:
    tree = build_tree(plan(LEAF, RunPolicy.FOREVER, name="sort parts"), registry)
    assert isinstance(tree.root, Root)
    assert (tree.root.id, tree.root.name, tree.root.policy) == (
        ROOT_ID,
        "sort parts",
        RunPolicy.FOREVER,
    )
    assert tree.root.children[0].id == LEAF.id


def test_operation_leaves_get_kind_defaults_fixed_values_and_refs(
    registry: CapabilityRegistry,
) -> None:
    cond = op("debug.check_param", "is five", value="$N", expected=5)
    tree = build_tree(plan(cond, parameters=[ParameterDecl("N", ParamType.NUMBER, 5)]), registry)
    node = tree.nodes[cond.id]
    assert isinstance(node, OperationLeaf)
    assert (node.op_kind, node.kind, node.is_condition) == (
        OperationKind.CONDITION,
        "condition",
        True,
    )
    assert tree.tick() is SUCCESS


def test_port_defaults_fill_unbound_inputs(registry: CapabilityRegistry) -> None:
    tree = build_tree(plan(op("debug.running")), registry)  # ticks defaults to 3
    assert [tree.tick() for _ in range(4)] == [RUNNING] * 3 + [SUCCESS]


def test_clock_and_blackboard_are_passed_in(registry: CapabilityRegistry, clock: FakeClock) -> None:
    board = Blackboard()
    board.set("START", 1)
    tree = build_tree(
        plan(logic(NodeKind.WAIT, seconds=1.0)), registry, clock=clock, blackboard=board
    )
    assert tree.blackboard is board and tree.ctx.clock is clock
    assert tree.tick() is RUNNING
    clock.advance(1.0)
    assert tree.tick() is SUCCESS


def test_aliases_of_renamed_operations_build(clock: FakeClock) -> None:
    cap = Capability("demo", "a demo")

    class Go:
        MANIFEST = OperationManifest(
            "demo.go", OperationKind.ACTION, "go", "demo", aliases=("demo.old_go",)
        )

        def __init__(self, env: CapabilityEnv) -> None:
            pass

        def start(self, call: OperationCall) -> Job:
            return Job.done()

    cap.add(Go)
    spec = op("demo.old_go")
    tree = build_tree(plan(spec), CapabilityRegistry([cap]))
    assert tree.tick() is SUCCESS


# ---------------------------------------------------------------------- errors


def build_error(registry: CapabilityRegistry, spec: PlanSpec) -> BuildError:
    with pytest.raises(BuildError) as info:
        build_tree(spec, registry)
    assert isinstance(info.value, EngineError)
    return info.value


def test_unknown_operation_names_the_path(registry: CapabilityRegistry) -> None:
    spec = plan(logic(NodeKind.SEQUENCE, LEAF, op("debug.teleport", "beam me"), name="main"))
    err = build_error(registry, spec)
    assert err.path == "main/beam me[1]"
    assert "unknown operation 'debug.teleport'" in str(err)


def test_unbound_required_input(registry: CapabilityRegistry) -> None:
    err = build_error(registry, plan(op("debug.pretend_move", "go")))
    assert str(err) == "go: parameter 'target' is not set"


def test_missing_operation_id(registry: CapabilityRegistry) -> None:
    spec = plan(logic(NodeKind.OPERATION, name="nothing"))
    assert "needs an operation id" in str(build_error(registry, spec))


def test_a_decorator_with_two_children(registry: CapabilityRegistry) -> None:
    spec = plan(
        logic(NodeKind.SEQUENCE, logic(NodeKind.INVERTER, LEAF, op("debug.fail"), name="not"))
    )
    err = build_error(registry, spec)
    assert err.path == "sequence/not[0]"
    assert "needs exactly one child, got 2" in str(err)


@pytest.mark.parametrize(
    ("kind", "config", "match"),
    [
        (
            NodeKind.REPEAT,
            {"count": 0},
            "'count' must be a whole number of at least 1, or -1 for no limit, not 0",
        ),
        (NodeKind.RETRY, {"count": -2}, "'count' must be a whole number of at least 1, or -1"),
        (NodeKind.TIMEOUT, {"seconds": -1}, "must be a number of seconds above 0, not -1"),
        (
            NodeKind.PARALLEL,
            {"success": "most"},
            "'success' must be one of all, any or a count, not 'most'",
        ),
        (NodeKind.REPEAT, {}, "repeat needs a value for 'count'"),
        (NodeKind.RETRY, {"count": 2, "tries": 3}, "retry has no setting 'tries'"),
    ],
)
def test_bad_settings(
    registry: CapabilityRegistry, kind: NodeKind, config: dict[str, Any], match: str
) -> None:
    assert match in str(build_error(registry, plan(logic(kind, LEAF, **config))))


def test_a_leaf_with_children_is_refused(registry: CapabilityRegistry) -> None:
    bad = op("debug.succeed", "parent leaf")
    bad.children.append(op("debug.succeed"))
    err = build_error(registry, plan(logic(NodeKind.SEQUENCE, bad)))
    assert err.path == "sequence/parent leaf[0]"
    assert "cannot have children" in str(err)
    wait = logic(NodeKind.WAIT, LEAF, seconds=1)
    assert "wait node cannot have children" in str(build_error(registry, plan(wait)))


def test_a_failing_operation_factory_is_a_build_error() -> None:
    cap = Capability("arm", "needs an arm")

    class Move:
        MANIFEST = OperationManifest("arm.move", OperationKind.ACTION, "move", "arm")

        def __init__(self, env: CapabilityEnv) -> None:
            env.interface("arm")  # the null cell has none: CapabilityError

        def start(self, call: OperationCall) -> Job:
            return Job.done()

    cap.add(Move)
    with pytest.raises(
        BuildError, match=r"cannot create operation 'arm\.move': CapabilityError: .*no 'arm'"
    ):
        build_tree(plan(op("arm.move", "move")), CapabilityRegistry([cap]))


def test_a_plan_without_a_tree(registry: CapabilityRegistry) -> None:
    assert "the plan has no tree" in str(build_error(registry, PlanSpec(name="empty")))


def test_a_parameter_with_a_value_of_the_wrong_type(registry: CapabilityRegistry) -> None:
    spec = plan(LEAF, parameters=[ParameterDecl("SPEED", ParamType.NUMBER, "fast")])
    err = build_error(registry, spec)
    assert err.path == "parameters/SPEED"
    assert "holds Number, not str 'fast'" in str(err)


def test_an_output_bound_to_a_fixed_value_is_not_written(registry: CapabilityRegistry) -> None:
    # validation reports it as an error; the builder just does not store the result
    spec = op("debug.query", value=3, result=4)
    tree = build_tree(plan(spec), registry)
    assert tree.tick() is SUCCESS
    assert tree.blackboard.snapshot() == {}


def test_manifest_ports() -> None:
    manifest = OperationManifest(
        "x.y",
        OperationKind.QUERY,
        "doc",
        "x",
        (
            PortSpec("a", (ParamType.NUMBER,)),
            PortSpec("b", (ParamType.POSE,), Direction.OUT, default=None),
        ),
    )
    assert [p.name for p in manifest.inputs] == ["a"] and [p.name for p in manifest.outputs] == [
        "b"
    ]
    a, b = manifest.port("a"), manifest.port("b")
    assert a is not None and b is not None
    assert a.required and not b.required
    assert manifest.port("zzz") is None and b.type is ParamType.POSE
