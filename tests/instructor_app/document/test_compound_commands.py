"""Compound edits are one command each (children done in order, undone in reverse): one undo
step with the text the Edit menu shows, and undo and redo give back the plan byte for byte.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from engine.spec import Binding, NodeKind, NodeLayout, NodeSpec, ParameterDecl, SubtreeSpec
from engine.tree import RunPolicy
from engine.types import ParamType, Pose, Waypoint
from instructor_app.document.commands import CompoundCommand, RenamePlanCommand
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.document.subtree_edits import SubtreeEditor


@pytest.fixture
def doc(qapp: Any, figure3_path: Path) -> PlanDocument:
    document = PlanDocument()
    document.open(figure3_path)
    return document


def named(document: PlanDocument, name: str) -> str:
    return next(n.id for _, n in document.plan.walk() if n.name == name)


def one_step(document: PlanDocument, edit: Any, text: str) -> None:
    """``edit`` is one undo step called ``text``; undo and redo round-trip the bytes."""
    before, depth = document.serialized(), document.undo_stack.count()
    edit()
    after = document.serialized()
    assert after != before
    assert document.undo_stack.count() == depth + 1
    assert document.undo_stack.undoText() == text
    document.undo_stack.undo()
    assert document.serialized() == before
    document.undo_stack.redo()
    assert document.serialized() == after


def test_deleting_siblings_together_puts_them_back_in_their_places(doc: PlanDocument) -> None:
    root = doc.plan.tree
    assert root is not None and len(root.children) >= 2
    first, second = root.children[0].id, root.children[1].id
    one_step(doc, lambda: doc.remove_nodes([first, second]), "Delete nodes")
    assert doc.plan.find(first) is None and doc.plan.find(second) is None
    command = doc.undo_stack.command(doc.undo_stack.count() - 1)
    assert isinstance(command, CompoundCommand) and len(command.parts) == 2


def test_deleting_one_node_is_named_after_it(doc: PlanDocument) -> None:
    node = named(doc, "transfer")
    one_step(doc, lambda: doc.remove_nodes([node]), "Delete transfer")
    with pytest.raises(DocumentError):
        doc.remove_nodes([])


def test_moving_to_the_end_drops_the_hand_placed_position_in_the_same_step(
    doc: PlanDocument,
) -> None:
    node, target = named(doc, "detect CUP"), named(doc, "transfer")
    doc.set_layout({node: NodeLayout(10.0, 20.0)})
    one_step(doc, lambda: doc.move_to_end(node, target, {node: None}), "Move detect CUP")
    assert doc.locate(node)[0] == target and node not in doc.plan.layout
    assert doc.locate(node)[1] == len(doc.node(target).children) - 1


def test_moving_to_where_it_is_only_changes_the_layout(doc: PlanDocument) -> None:
    node = named(doc, "transfer")
    parent, _, _ = doc.locate(node)
    assert parent is not None
    doc.move_node(node, parent, len(doc.node(parent).children) - 1)  # last already
    depth = doc.undo_stack.count()
    doc.move_to_end(node, parent)
    assert doc.undo_stack.count() == depth  # nothing moves, nothing placed: no step
    doc.set_layout({node: NodeLayout(5.0, 5.0)})
    one_step(doc, lambda: doc.move_to_end(node, parent, {node: None}), "Move transfer")


def test_replacing_a_waypoint_changes_the_list_and_its_bindings_in_one_step(
    doc: PlanDocument,
) -> None:
    old = Waypoint("above bin", pose=Pose((0.4, 0.2, 0.3)))
    doc.store_waypoints([old])
    a, b = named(doc, "detect CUP"), named(doc, "detect BIN")
    doc.set_param(a, "target", Binding.fixed(old, ParamType.WAYPOINT))
    doc.set_param(b, "target", Binding.fixed(old, ParamType.WAYPOINT))
    new = Waypoint("over bin", pose=Pose((0.4, 0.2, 0.5)))
    one_step(doc, lambda: doc.replace_waypoint("above bin", new), "Change the waypoint 'above bin'")
    assert doc.plan.waypoints == [new]
    assert doc.node(a).params["target"].value == new == doc.node(b).params["target"].value
    with pytest.raises(DocumentError, match="already a waypoint"):
        doc.store_waypoints([old])
        doc.replace_waypoint("above bin", new)


def test_teaching_a_waypoint_binds_the_port_in_the_same_step(doc: PlanDocument) -> None:
    node = named(doc, "detect CUP")
    taught = Waypoint("new place", pose=Pose((0.1, 0.2, 0.3)))
    one_step(
        doc,
        lambda: doc.replace_waypoint("new place", taught, "Teach 'new place'", (node, "target")),
        "Teach 'new place'",
    )
    assert doc.plan.waypoints[-1] == taught
    assert doc.node(node).params["target"] == Binding.fixed(taught, ParamType.WAYPOINT)


@pytest.mark.parametrize(
    ("edit", "text"),
    [
        (lambda d: d.rename_plan("another name"), "Change the plan's name"),
        (lambda d: d.set_run_policy(RunPolicy.FOREVER), "Change the plan's run policy"),
        (lambda d: d.set_reset_cell(not d.plan.reset_cell), "Change the plan's reset cell"),
        (lambda d: d.set_give_up_after(9), "Change the plan's limit of identical failures"),
        (
            lambda d: d.declare_parameter(ParameterDecl("SPEED", ParamType.NUMBER, 0.5)),
            "Change the plan's parameters",
        ),
        (
            lambda d: d.store_waypoints([Waypoint("w", pose=Pose())]),
            "Change the plan's waypoints",
        ),
    ],
)
def test_plan_wide_edits_keep_their_undo_text(doc: PlanDocument, edit: Any, text: str) -> None:
    one_step(doc, lambda: edit(doc), text)


def test_declaring_a_parameter_again_replaces_it_in_place(doc: PlanDocument) -> None:
    doc.declare_parameter(ParameterDecl("A", ParamType.NUMBER, 1.0))
    doc.declare_parameter(ParameterDecl("B", ParamType.NUMBER, 2.0))
    one_step(
        doc,
        lambda: doc.declare_parameter(ParameterDecl("A", ParamType.NUMBER, 3.0)),
        "Change the plan's parameters",
    )
    assert [(p.name, p.value) for p in doc.plan.parameters][-2:] == [("A", 3.0), ("B", 2.0)]


def test_storing_and_removing_waypoints(doc: PlanDocument) -> None:
    a, b = Waypoint("a", pose=Pose()), Waypoint("b", pose=Pose())
    doc.store_waypoints([a, b])
    depth = doc.undo_stack.count()
    doc.store_waypoints([a])  # the same waypoint again: nothing changes, no step
    assert doc.undo_stack.count() == depth
    moved = Waypoint("a", pose=Pose((1.0, 0.0, 0.0)))
    one_step(doc, lambda: doc.store_waypoints([moved]), "Change the plan's waypoints")
    assert [w.name for w in doc.plan.waypoints] == ["a", "b"] and doc.plan.waypoints[0] == moved
    one_step(doc, lambda: doc.remove_waypoint("a"), "Change the plan's waypoints")
    assert [w.name for w in doc.plan.waypoints] == ["b"]
    with pytest.raises(DocumentError):
        doc.remove_waypoint("nowhere")


def test_a_plan_command_is_named_for_the_edit(doc: PlanDocument) -> None:
    doc.push(RenamePlanCommand(doc, "pushed"))
    assert doc.plan.name == "pushed"


# ---------------------------------------------------------------------- library subtrees


def _subtree(version: int = 1) -> SubtreeSpec:
    inside = NodeSpec(NodeKind.OPERATION, "inside", "in1", op="debug.succeed")
    return SubtreeSpec(
        "sub1", "Part", NodeSpec(NodeKind.SEQUENCE, "part", "p1", children=[inside]), version
    )


@pytest.fixture
def plain(qapp: Any) -> PlanDocument:
    document = PlanDocument()
    document.add_node(NodeSpec(NodeKind.SEQUENCE, name="top"))
    document.undo_stack.clear()
    return document


def test_inserting_an_instance_embeds_its_definition_in_the_same_step(
    plain: PlanDocument,
) -> None:
    top = plain.plan.tree.id  # type: ignore[union-attr]
    editor = SubtreeEditor(plain)
    one_step(plain, lambda: editor.insert_instance(_subtree(), top), "Insert Part")
    assert [s.ref for s in plain.plan.subtrees] == [_subtree().ref]


def test_detach_and_update_drop_the_definitions_no_instance_runs(plain: PlanDocument) -> None:
    top = plain.plan.tree.id  # type: ignore[union-attr]
    editor = SubtreeEditor(plain)
    instance = editor.insert_instance(_subtree(), top)
    label = plain.node(instance).label
    one_step(plain, lambda: editor.update(instance, _subtree(2)), f"Update {label} to version 2")
    assert [s.version for s in plain.plan.subtrees] == [2]
    one_step(plain, lambda: editor.detach(instance), f"Detach {label}")
    assert plain.plan.subtrees == []


def test_nodes_saved_as_a_subtree_become_its_instance_in_one_step(plain: PlanDocument) -> None:
    top = plain.plan.tree.id  # type: ignore[union-attr]
    part = plain.add_node(NodeSpec(NodeKind.SEQUENCE, name="part"), top)
    plain.add_node(NodeSpec(NodeKind.OPERATION, name="inside", op="debug.succeed"), part)
    plain.set_layout({part: NodeLayout(3.0, 4.0)})
    editor = SubtreeEditor(plain)
    saved = _subtree()
    one_step(plain, lambda: editor.use_saved(part, saved), "Save part as the subtree Part")
    instance = plain.node(top).children[0]
    assert instance.kind is NodeKind.SUBTREE and plain.plan.layout[instance.id] == NodeLayout(3, 4)


def test_a_paste_that_brings_definitions_is_one_step(plain: PlanDocument) -> None:
    top = plain.plan.tree.id  # type: ignore[union-attr]
    instance = SubtreeEditor(plain).insert_instance(_subtree(), top)
    clip = plain.subtree_json(instance)
    target = PlanDocument()
    root = target.add_node(NodeSpec(NodeKind.SEQUENCE, name="top"))
    one_step(target, lambda: target.paste(clip, root), f"Paste {plain.node(instance).label}")
    assert [s.ref for s in target.plan.subtrees] == [_subtree().ref]
