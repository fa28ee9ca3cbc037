"""Save a selection as a subtree, instantiate it, detach and update instances, find usages."""

from __future__ import annotations

from pathlib import Path

import pytest
from bt_fakes import logic, op, plan
from test_subtrees import pick_subtree, two_instances

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.files import dump_plan, loads_plan, save_plan
from engine.library import Library
from engine.spec import Binding, NodeKind, PlanSpec, SubtreePort, SubtreeSpec
from engine.status import SUCCESS
from engine.subtree_ops import (
    OpenPort,
    detach,
    find_usages,
    instance_of,
    make_subtree,
    ports_bound_elsewhere,
    ports_of,
    update,
)
from engine.types import ParamType
from engine.validation import validate_plan


def _selection_plan() -> PlanSpec:
    """A plan whose middle sequence is the part to save: it reads SEEN and writes KEPT."""
    part = logic(
        NodeKind.SEQUENCE,
        op("debug.query", "find", value="cup", result="$FOUND"),
        op("debug.check_param", "is what was seen", value="$FOUND", expected="$SEEN"),
        op("debug.set_param", "keep", value="$FOUND", name="$KEPT"),
        name="Find",
    )
    tree = logic(
        NodeKind.SEQUENCE,
        op("debug.set_param", "see", value="cup", name="$SEEN"),
        part,
        op("debug.check_param", "kept", value="$KEPT", expected="cup"),
    )
    return plan(tree)


def _save_and_instantiate(
    registry: CapabilityRegistry, library: Library, spec: PlanSpec, open_ports: list[OpenPort]
) -> PlanSpec:
    """Save the part to the library, read it back and put an instance where the part was."""
    assert spec.tree is not None
    part = spec.tree.children[1]
    made = make_subtree(part, "Find", ports_of(spec, registry), open_ports, {"KEPT": "the find"})
    saved = library.save(made, "test")
    loaded = library.scan().latest(saved.id)
    assert loaded == saved and saved.version == 1
    spec.tree.children[1] = instance_of(loaded, part, open_ports)
    spec.subtrees.append(loaded)
    return spec


@pytest.mark.parametrize("open_value", [False, True], ids=["all fixed", "value left open"])
def test_save_and_instantiate_round_trip(
    registry: CapabilityRegistry, tmp_path: Path, open_value: bool
) -> None:
    library = Library(tmp_path, shipped=()).scan()
    spec = _selection_plan()
    first = spec.tree.children[1].children[0]  # type: ignore[union-attr]
    opened = [OpenPort(first.id, "value", "OBJECT", "what to find")] if open_value else []
    made = _save_and_instantiate(registry, library, spec, opened)
    sub = made.subtrees[0]
    assert [p.name for p in sub.outputs] == ["KEPT"]
    expected_inputs = (["OBJECT"] if open_value else []) + ["SEEN"]  # SEEN is read from outside
    assert [p.name for p in sub.inputs] == expected_inputs
    if open_value:
        assert sub.inputs[0].default == "cup" and sub.inputs[0].doc == "what to find"
        assert made.tree.children[1].params["OBJECT"] == Binding.fixed("cup", ParamType.TEXT)  # type: ignore[union-attr]
    assert validate_plan(made, registry) == []
    again = loads_plan(dump_plan(made))
    assert dump_plan(again) == dump_plan(made)
    assert build_tree(again, registry).tick_until_done(1000) is SUCCESS


def test_reparameterized_instance_runs_with_its_new_value(
    registry: CapabilityRegistry, tmp_path: Path
) -> None:
    library = Library(tmp_path, shipped=()).scan()
    spec = _selection_plan()
    first = spec.tree.children[1].children[0]  # type: ignore[union-attr]
    made = _save_and_instantiate(registry, library, spec, [OpenPort(first.id, "value", "OBJECT")])
    made.tree.children[1].params["OBJECT"] = Binding.fixed("plate", ParamType.TEXT)  # type: ignore[union-attr]
    made.tree.children[0].params["value"] = Binding.fixed("plate", ParamType.TEXT)  # type: ignore[union-attr]
    made.tree.children[2].params["expected"] = Binding.fixed("plate", ParamType.TEXT)  # type: ignore[union-attr]
    tree = build_tree(made, registry)
    assert tree.tick_until_done(1000) is SUCCESS
    assert tree.blackboard.get("KEPT") == "plate"


def test_detach_writes_inputs_in_and_renames_private_names(registry: CapabilityRegistry) -> None:
    spec = two_instances()
    assert spec.tree is not None
    for index in (1, 2):
        spec.tree.children[index] = detach(spec, spec.tree.children[index])
    spec.subtrees.clear()
    assert validate_plan(spec, registry) == []
    first, second = spec.tree.children[1], spec.tree.children[2]
    assert first.kind is NodeKind.SEQUENCE and first.name == "Pick A"
    assert first.children[0].params["value"] == Binding.fixed("a", ParamType.TEXT)
    assert second.children[0].params["value"] == Binding.reference("WANTED")
    assert first.children[0].params["result"].ref == "PICKED"
    assert second.children[0].params["result"].ref == "PICKED_2"
    assert second.children[1].params["name"].ref == "GOT_B"
    board = build_tree(spec, registry)
    assert board.tick_until_done(1000) is SUCCESS


def test_update_keeps_the_bindings_of_ports_that_remain() -> None:
    spec = two_instances()
    newer = pick_subtree(version=2)
    newer.inputs = newer.inputs[:0]  # the new version has no OBJECT input
    moved = update(spec.tree.children[1], newer)  # type: ignore[union-attr]
    assert moved.subtree == newer.ref and set(moved.params) == {"RESULT"}


def test_find_usages_in_a_folder_names_broken_files(tmp_path: Path) -> None:
    save_plan(two_instances(), tmp_path / "a.costar.json")
    (tmp_path / "sub").mkdir()
    save_plan(plan(op("debug.succeed")), tmp_path / "sub" / "b.costar.json")
    (tmp_path / "sub" / "broken.costar.json").write_text("{")
    usages, problems = find_usages(tmp_path, "test.pick")
    assert [(u.file.name, u.path, u.version) for u in usages] == [
        ("a.costar.json", "sequence/Pick A[1]", 1),
        ("a.costar.json", "sequence/Pick B[2]", 1),
    ]
    assert len(problems) == 1 and "broken.costar.json" in problems[0]


def test_one_input_may_feed_several_parameters(registry: CapabilityRegistry) -> None:
    spec = _selection_plan()
    part = spec.tree.children[1]  # type: ignore[union-attr]
    find, check = part.children[0], part.children[1]
    opened = [OpenPort(find.id, "value", "OBJECT"), OpenPort(check.id, "expected", "OBJECT")]
    made = make_subtree(part, "Find", ports_of(spec, registry), opened)
    assert [p.name for p in made.inputs] == ["OBJECT"]
    inner = made.tree.children
    assert inner[0].params["value"] == inner[1].params["expected"] == Binding.reference("OBJECT")


def test_ports_bound_elsewhere_are_the_first_bindings_of_the_same_name_and_type() -> None:
    spec = two_instances()
    sub = spec.subtrees[0]
    assert ports_bound_elsewhere(spec, sub) == {
        "OBJECT": Binding.fixed("a", ParamType.TEXT),  # Pick A's, the first in tick order
        "RESULT": Binding.reference("GOT_A"),
    }
    other = SubtreeSpec(
        id="test.other", name="Other", tree=sub.tree,
        inputs=[SubtreePort("OBJECT", ParamType.POSE, "another type")],
    )  # fmt: skip
    assert ports_bound_elsewhere(spec, other) == {}
    assert ports_bound_elsewhere(plan(logic(NodeKind.SEQUENCE)), sub) == {}
