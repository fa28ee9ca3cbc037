"""Subtree instances: files round-trip, scoped build and run, validation of bindings and scopes."""

from __future__ import annotations

import pytest
from bt_fakes import logic, op, plan

from capabilities.base import CapabilityRegistry
from engine.build import BuildError, build_tree
from engine.files import dump_plan, loads_plan
from engine.instances import runtime_paths
from engine.spec import (
    Binding,
    NodeKind,
    NodeSpec,
    PlanSpec,
    SubtreePort,
    SubtreeSpec,
)
from engine.status import FAILURE, SUCCESS
from engine.types import ParamType
from engine.validation import ERROR, WARNING, Problem, validate_plan


def pick_subtree(version: int = 1, shared: tuple[str, ...] = ()) -> SubtreeSpec:
    """Reads its input OBJECT, keeps a private PICKED, declares the output RESULT."""
    tree = logic(
        NodeKind.SEQUENCE,
        op("debug.query", "find", value="$OBJECT", result="$PICKED"),
        op("debug.set_param", "keep", value="$PICKED", name="$RESULT"),
        name="Pick",
    )
    return SubtreeSpec(
        id="test.pick",
        name="Pick",
        tree=tree,
        version=version,
        date="2026-11-24T19:40:00Z",
        description="Finds an object.",
        inputs=[SubtreePort("OBJECT", ParamType.TEXT, "what to pick")],
        outputs=[SubtreePort("RESULT", ParamType.ANY, "what was picked")],
        shared_names=list(shared),
    )


def instance(subtree: SubtreeSpec, name: str, **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.SUBTREE, name=name, subtree=subtree.ref, params=dict(params))


def two_instances() -> PlanSpec:
    sub = pick_subtree()
    first = instance(
        sub, "Pick A", OBJECT=Binding.fixed("a", ParamType.TEXT), RESULT=Binding.reference("GOT_A")
    )
    second = instance(
        sub, "Pick B", OBJECT=Binding.reference("WANTED"), RESULT=Binding.reference("GOT_B")
    )
    tree = logic(
        NodeKind.SEQUENCE,
        op("debug.set_param", "want b", value="b", name="$WANTED"),
        first,
        second,
        op("debug.check_param", "got a", value="$GOT_A", expected="a"),
        op("debug.check_param", "got b", value="$GOT_B", expected="b"),
    )
    return plan(tree, subtrees=[sub])


def errors(problems: list[Problem]) -> list[str]:
    return [str(p) for p in problems if p.severity == ERROR]


def test_plan_with_instances_round_trips_byte_for_byte() -> None:
    text = dump_plan(two_instances())
    assert '"format_version": 3' in text and '"kind": "subtree"' in text
    again = loads_plan(text)
    assert dump_plan(again) == text
    assert again.subtrees[0].inputs[0] == SubtreePort("OBJECT", ParamType.TEXT, "what to pick")


def test_plain_plan_is_still_written_as_version_2() -> None:
    assert '"format_version": 2' in dump_plan(plan(op("debug.succeed")))


def test_two_instances_of_one_subtree_do_not_collide(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    assert validate_plan(spec, registry) == []
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(1000) is SUCCESS
    board = tree.blackboard.snapshot()
    assert board["GOT_A"] == "a" and board["GOT_B"] == "b"
    private = sorted(k for k in board if k.endswith("/PICKED"))
    assert len(private) == 2 and "PICKED" not in board
    assert {board[k] for k in private} == {"a", "b"}


def test_inner_runtime_ids_are_prefixed_by_the_instance(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    tree = build_tree(spec, registry)
    ids = [node.id for node in tree.iterate()]
    first, second = spec.tree.children[1], spec.tree.children[2]  # type: ignore[union-attr]
    inner = spec.subtrees[0].tree.children[0].id
    assert f"{first.id}/{inner}" in ids and f"{second.id}/{inner}" in ids


def test_unbound_input_and_wrong_type_reported_at_the_instance(
    registry: CapabilityRegistry,
) -> None:
    spec = two_instances()
    first = spec.tree.children[1]  # type: ignore[union-attr]
    del first.params["OBJECT"]
    spec.tree.children[2].params["OBJECT"] = Binding.fixed(3.0, ParamType.NUMBER)  # type: ignore[union-attr]
    found = errors(validate_plan(spec, registry))
    assert any("Pick A" in e and "[OBJECT]" in e and "needs a value" in e for e in found)
    assert any("Pick B" in e and "needs a Text" in e for e in found)
    with pytest.raises(BuildError, match="input 'OBJECT' of 'Pick' is not set"):
        build_tree(spec, registry)


def test_missing_subtree_reported_with_the_node_path(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    spec.subtrees.clear()
    found = errors(validate_plan(spec, registry))
    assert any(
        e.startswith("error: sequence/Pick A[1]") and "neither in this plan" in e for e in found
    )
    with pytest.raises(BuildError, match=r"Pick A\[1\]: the plan holds no subtree 'test.pick'"):
        build_tree(spec, registry)


def test_problem_inside_reported_under_the_instance_path(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    spec.subtrees[0].tree.children[0].op = "debug.nonesuch"
    found = errors(validate_plan(spec, registry))
    assert any("Pick A[1]/Pick/find[0]" in e and "no operation" in e for e in found)


def test_shared_name_written_by_two_instances_is_a_collision(
    registry: CapabilityRegistry,
) -> None:
    sub = pick_subtree(shared=("PICKED",))
    tree = logic(
        NodeKind.SEQUENCE,
        instance(sub, "Pick A", OBJECT=Binding.fixed("a", ParamType.TEXT)),
        instance(sub, "Pick B", OBJECT=Binding.fixed("b", ParamType.TEXT)),
    )
    problems = validate_plan(plan(tree, subtrees=[sub]), registry)
    collisions = [p for p in problems if p.severity == WARNING and "crosses scopes" in p.message]
    assert {p.path for p in collisions} == {"sequence/Pick A[0]", "sequence/Pick B[1]"}
    # and at run time the shared name is one name: the second instance overwrote the first
    built = build_tree(plan(tree, subtrees=[sub]), registry)
    assert built.tick_until_done(1000) is SUCCESS
    assert built.blackboard.get("PICKED") == "b"


def test_shared_name_also_written_outside_is_a_collision(registry: CapabilityRegistry) -> None:
    sub = pick_subtree(shared=("PICKED",))
    tree = logic(
        NodeKind.SEQUENCE,
        op("debug.set_param", "mine", value="x", name="$PICKED"),
        instance(sub, "Pick A", OBJECT=Binding.fixed("a", ParamType.TEXT)),
    )
    problems = validate_plan(plan(tree, subtrees=[sub]), registry)
    found = [p for p in problems if "crosses scopes" in p.message]
    assert len(found) == 1 and "'mine'" in found[0].message


def test_newer_library_version_is_a_warning_with_update() -> None:
    class Library:
        def latest(self, subtree_id: str) -> SubtreeSpec | None:
            return pick_subtree(version=2) if subtree_id == "test.pick" else None

    from capabilities.base import CapabilityRegistry as Registry
    from capabilities.debug import capability

    problems = validate_plan(two_instances(), Registry([capability()]), Library())
    newer = [p for p in problems if "newer version" in p.message]
    assert [p.severity for p in newer] == [WARNING, WARNING]
    assert "version 2" in newer[0].message and "update" in newer[0].message


def test_reference_input_is_read_when_the_instance_starts(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    spec.tree.children[0].params["value"] = Binding.fixed("c", ParamType.TEXT)  # type: ignore[union-attr]
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(1000) is FAILURE  # "got b" fails: B picked "c"
    assert tree.blackboard.get("GOT_B") == "c"


def test_failure_inside_fails_the_instance_with_its_message(registry: CapabilityRegistry) -> None:
    sub = pick_subtree()
    sub.tree.children.append(op("debug.fail", "oops", message="dropped it"))
    tree = logic(
        NodeKind.SEQUENCE, instance(sub, "Pick A", OBJECT=Binding.fixed("a", ParamType.TEXT))
    )
    built = build_tree(plan(tree, subtrees=[sub]), registry)
    assert built.tick_until_done(1000) is FAILURE
    node = next(n for n in built.iterate() if n.name == "Pick A")
    assert node.status is FAILURE and "oops" in node.message


def test_runtime_paths_name_the_insides_of_instances(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    paths = runtime_paths(spec)
    first = spec.tree.children[1]  # type: ignore[union-attr]
    find = spec.subtrees[0].tree.children[0]
    assert paths[f"{first.id}/{find.id}"] == "sequence/Pick A[1]/Pick/find[0]"
    built = {node.id for node in build_tree(spec, registry).iterate()} - {"root"}
    assert built <= set(paths)  # every runtime node has a path
