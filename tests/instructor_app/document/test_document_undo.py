"""PlanDocument: every edit is one undo command; undo restores the serialized plan byte for
byte and redo the later one, for each command kind and for random sequences.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from engine.spec import Binding, NodeKind, NodeLayout, NodeSpec, ParameterDecl, PlanSpec
from engine.tree import RunPolicy
from engine.types import ParamType, Pose, Waypoint
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError

Edit = Callable[[PlanDocument], Any]


@pytest.fixture
def doc(qapp: Any, figure3_path: Path) -> PlanDocument:
    document = PlanDocument()
    document.open(figure3_path)
    return document


def named(document: PlanDocument, name: str) -> str:
    return next(n.id for _, n in document.plan.walk() if n.name == name)


def leaf(name: str = "new leaf") -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, name=name, op="debug.succeed")


def check_round_trip(document: PlanDocument, edit: Edit, commands: int = 1) -> None:
    """``edit`` pushes ``commands`` commands; undo gives back the bytes before, redo after."""
    before = document.serialized()
    depth = document.undo_stack.count()
    edit(document)
    after = document.serialized()
    assert after != before, "the edit changed nothing"
    assert document.undo_stack.count() == depth + commands
    assert document.dirty
    for _ in range(commands):
        document.undo_stack.undo()
    assert document.serialized() == before
    for _ in range(commands):
        document.undo_stack.redo()
    assert document.serialized() == after


EDITS: dict[str, Edit] = {
    "add leaf": lambda d: d.add_node(leaf(), named(d, "transfer")),
    "add at index 0": lambda d: d.add_node(leaf(), named(d, "transfer"), 0),
    "add with layout": lambda d: _add_placed(d),
    "remove leaf": lambda d: d.remove_node(named(d, "pose of CUP")),
    "remove subtree": lambda d: d.remove_node(named(d, "transfer or wait")),
    "remove root": lambda d: d.remove_node(d.plan.tree.id),
    "reparent": lambda d: d.move_node(named(d, "detect CUP"), named(d, "transfer"), 1),
    "reorder": lambda d: d.move_node(named(d, "pose of CUP"), named(d, "transfer"), 0),
    "set param fixed": lambda d: d.set_param(
        named(d, "detect CUP"), "ticks", Binding.fixed(7.0, ParamType.NUMBER)
    ),
    "set param reference": lambda d: d.set_param(
        named(d, "detect CUP"), "then", Binding.reference("WHAT")
    ),
    "unbind param": lambda d: d.set_param(named(d, "detect CUP"), "ticks", None),
    "set setting": lambda d: d.set_param(
        named(d, "detect objects"), "success", Binding.fixed("any", ParamType.TEXT)
    ),
    "rename": lambda d: d.rename(named(d, "detect BIN"), "find the bin"),
    "collapse": lambda d: d.set_collapsed(named(d, "transfer"), True),
    "layout": lambda d: d.set_layout(
        {named(d, "transfer"): NodeLayout(5.0, 6.0), d.plan.tree.id: NodeLayout(1.0, 2.0)}
    ),
    "plan name": lambda d: d.rename_plan("renamed plan"),
    "plan run policy": lambda d: d.set_run_policy(RunPolicy.FOREVER),
    "plan reset cell": lambda d: d.set_reset_cell(not d.plan.reset_cell),
    "plan give up after": lambda d: d.set_give_up_after(d.plan.give_up_after + 1),
    "plan parameters": lambda d: d.declare_parameter(
        ParameterDecl("SPEED", ParamType.NUMBER, 0.25)
    ),
    "plan waypoints": lambda d: d.store_waypoints(
        [Waypoint("above bin", pose=Pose((0.4, 0.2, 0.3)))]
    ),
    "paste": lambda d: d.paste(d.subtree_json(named(d, "transfer")), named(d, "transfer or wait")),
    "duplicate": lambda d: d.duplicate(named(d, "transfer")),
    "cut": lambda d: d.cut(named(d, "transfer")),
}


def _add_placed(document: PlanDocument) -> str:
    node = leaf("placed")
    return document.add_node(node, named(document, "transfer"), None, {node.id: NodeLayout(1, 2)})


@pytest.mark.parametrize("name", sorted(EDITS))
def test_each_command_undoes_and_redoes_byte_for_byte(doc: PlanDocument, name: str) -> None:
    check_round_trip(doc, EDITS[name])


def test_adding_the_root_to_an_empty_plan_round_trips(qapp: Any) -> None:
    document = PlanDocument()
    check_round_trip(document, lambda d: d.add_node(NodeSpec(NodeKind.SEQUENCE, name="top")))
    assert document.plan.tree is not None and document.plan.tree.name == "top"


def test_paste_and_duplicate_give_fresh_ids_and_copy_the_layout(doc: PlanDocument) -> None:
    transfer = named(doc, "transfer")
    doc.set_layout({transfer: NodeLayout(40.0, 50.0)})
    copy_id = doc.duplicate(transfer)
    parent, index, _ = doc.locate(copy_id)
    assert (parent, index) == (named(doc, "transfer or wait"), 1)
    ids = [n.id for _, n in doc.plan.walk()]
    assert len(ids) == len(set(ids))
    assert doc.plan.layout[copy_id] == NodeLayout(40.0, 50.0)


def test_a_sequence_of_edits_undoes_step_by_step(doc: PlanDocument) -> None:
    states = [doc.serialized()]
    for name in ("add leaf", "reparent", "set param fixed", "collapse", "cut", "rename"):
        EDITS[name](doc)
        states.append(doc.serialized())
    clip = doc.subtree_json(named(doc, "detect objects"))
    doc.paste(clip, named(doc, "transfer or wait"), 0)
    states.append(doc.serialized())
    for expected in reversed(states[:-1]):
        doc.undo_stack.undo()
        assert doc.serialized() == expected
    assert not doc.dirty
    for expected in states[1:]:
        doc.undo_stack.redo()
        assert doc.serialized() == expected


def test_rejected_edits_leave_the_document_untouched(doc: PlanDocument) -> None:
    before, depth = doc.serialized(), doc.undo_stack.count()
    with pytest.raises(DocumentError):
        doc.add_node(leaf(), named(doc, "pose of CUP"))  # a leaf takes no child
    with pytest.raises(DocumentError):
        doc.add_node(leaf())  # the plan already has a root
    with pytest.raises(DocumentError):
        doc.move_node(named(doc, "transfer or wait"), named(doc, "transfer"), 0)  # into itself
    with pytest.raises(DocumentError):
        doc.remove_node("no such node")
    with pytest.raises(DocumentError):
        doc.duplicate(doc.plan.tree.id)
    with pytest.raises(DocumentError):
        doc.paste("not a plan", named(doc, "transfer"))
    assert doc.serialized() == before and doc.undo_stack.count() == depth


def test_save_marks_clean_and_undo_past_it_marks_dirty(doc: PlanDocument, tmp_path: Path) -> None:
    seen: list[bool] = []
    doc.dirty_changed.connect(seen.append)
    EDITS["rename"](doc)
    doc.save(tmp_path / "plan.costar.json")
    assert not doc.dirty and seen == [True, False]
    doc.undo_stack.undo()
    assert doc.dirty and seen[-1] is True
    assert PlanDocument().serialized() != doc.serialized()


# ---------------------------------------------------------------------- random sequences


def _random_edit(document: PlanDocument, rng: random.Random) -> bool:
    """One random valid edit; False when the chosen edit did not apply."""
    nodes = [n for _, n in document.plan.walk()]
    if not nodes:
        document.add_node(NodeSpec(NodeKind.SEQUENCE, name="top"))
        return True
    node = rng.choice(nodes)
    parents = [n for n in nodes if n.kind in (NodeKind.SEQUENCE, NodeKind.SELECTOR)]
    choice = rng.randrange(9)
    try:
        if choice == 0 and parents:
            document.add_node(leaf(f"leaf {rng.randrange(1000)}"), rng.choice(parents).id)
        elif choice == 1 and node is not document.plan.tree:
            document.remove_node(node.id)
        elif choice == 2 and parents and node is not document.plan.tree:
            target = rng.choice(parents)
            # the index counts the target's children after the node was taken out
            places = len(target.children) + (0 if any(c is node for c in target.children) else 1)
            document.move_node(node.id, target.id, rng.randrange(places))
        elif choice == 3:
            document.rename(node.id, f"name {rng.randrange(1000)}")
        elif choice == 4 and node.kind is NodeKind.OPERATION:
            value = Binding.fixed(float(rng.randrange(10)), ParamType.NUMBER)
            document.set_param(node.id, "ticks", value)
        elif choice == 5:
            document.set_collapsed(node.id, rng.random() < 0.5)
        elif choice == 6:
            document.set_layout({node.id: NodeLayout(rng.uniform(0, 500), rng.uniform(0, 500))})
        elif choice == 7 and node is not document.plan.tree:
            document.duplicate(node.id)
        elif choice == 8:
            document.rename_plan(f"plan {rng.randrange(1000)}")
        else:
            return False
    except DocumentError:
        return False  # e.g. a move into its own subtree: refused, nothing pushed
    return True


@pytest.mark.parametrize("seed", [7, 2024])
def test_random_edit_sequences_undo_and_redo_byte_for_byte(qapp: Any, seed: int) -> None:
    rng = random.Random(seed)
    document = PlanDocument()
    document.load_text(_figure3_text(), None)
    document.undo_stack.setClean()
    states = [document.serialized()]
    while len(states) < 150:
        depth = document.undo_stack.count()
        if _random_edit(document, rng) and document.undo_stack.count() > depth:
            states.append(document.serialized())
        else:
            assert document.serialized() == states[-1]  # a refused edit changed nothing
    for expected in reversed(states[:-1]):
        document.undo_stack.undo()
        assert document.serialized() == expected
    for expected in states[1:]:
        document.undo_stack.redo()
        assert document.serialized() == expected


def _figure3_text() -> str:
    return (
        Path(__file__).resolve().parents[3] / "resources/examples/figure3_debug.costar.json"
    ).read_text()


def test_an_empty_plan_serializes(qapp: Any) -> None:
    assert "costar-plan" in PlanDocument().serialized()
    assert PlanSpec().tree is None


def test_move_to_a_place_that_does_not_exist_is_refused_and_loses_nothing(qtbot: object) -> None:
    from instructor_app.document import DocumentError, PlanDocument

    document = PlanDocument()
    document.load_text(_figure3_text(), None)
    before = document.serialized()
    root = document.plan.tree
    assert root is not None
    first = root.children[0]
    with pytest.raises(DocumentError, match="no place"):
        document.move_node(first.id, root.id, len(root.children))
    assert document.serialized() == before
    document.move_node(first.id, root.id, len(root.children) - 1)  # the last place exists
    assert document.plan.tree.children[-1].id == first.id
