"""CanvasView mirrors the document, and gestures on the canvas edit the document."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import QMimeData, QPointF, QRectF, Qt
from PySide6.QtGui import QDropEvent
from PySide6.QtWidgets import QApplication
from pytestqt.qtbot import QtBot

from bench.gui import build_plan
from engine.spec import Binding, NodeKind, NodeLayout, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType
from instructor_app.canvas import PALETTE_MIME, CanvasView
from instructor_app.canvas.style import STATUS_COLOURS
from instructor_app.document.editing import PlanDocument


def op_leaf(name: str = "", op: str = "motion.move_to") -> NodeSpec:
    return NodeSpec(
        NodeKind.OPERATION,
        name=name,
        op=op,
        params={
            "target": Binding.reference("CUP_POSE"),
            "object": Binding.fixed("CUP", ParamType.TEXT),
        },
    )


@pytest.fixture
def doc(qapp: Any) -> PlanDocument:
    document = PlanDocument()
    root = NodeSpec(NodeKind.SEQUENCE, name="root")
    pick = NodeSpec(NodeKind.SELECTOR, name="pick", children=[op_leaf("a"), op_leaf("b")])
    root.children = [
        pick,
        op_leaf("c"),
        NodeSpec(NodeKind.ITERATOR, name="loop", children=[op_leaf("d")]),
    ]
    document.load_text(_dump(PlanSpec(tree=root, name="t")), None)
    document.undo_stack.clear()
    return document


def _dump(plan: PlanSpec) -> str:
    from engine.files import dump_plan

    return dump_plan(plan)


@pytest.fixture
def view(qtbot: QtBot, doc: PlanDocument) -> Iterator[CanvasView]:
    canvas = CanvasView(doc)
    qtbot.addWidget(canvas)
    canvas.resize(900, 600)
    canvas.show()
    qtbot.waitExposed(canvas)
    yield canvas


def nid(doc: PlanDocument, name: str) -> str:
    return next(n.id for _, n in doc.plan.walk() if n.name == name)


def titles(view: CanvasView) -> set[str]:
    return {node.item.look.title for node in view.mirror.nodes.values()}


def test_opens_the_plan_with_one_item_per_node(view: CanvasView, doc: PlanDocument) -> None:
    assert view.node_count() == 7
    assert titles(view) == {"root", "pick", "a", "b", "c", "loop", "d"}
    a = view.item(nid(doc, "a"))
    assert set(a.look.lines) == {"target: CUP_POSE", 'object: "CUP"'}
    assert view.item(nid(doc, "pick")).look.symbol == "?"
    assert view.item(nid(doc, "root")).look.symbol == "->"
    # Children carry their place as a badge; tick order is left to right.
    assert [view.item(nid(doc, n)).index_badge for n in ("pick", "c", "loop")] == [1, 2, 3]
    xs = [view.item(nid(doc, n)).pos().x() for n in ("pick", "c", "loop")]
    assert xs == sorted(xs)
    # Links: one per non-root node.
    graph_nodes = view.graph.model.nodes
    assert set(graph_nodes) == {n.id for _, n in doc.plan.walk()}


def test_mirrors_add_remove_move_rename_and_their_undo(view: CanvasView, doc: PlanDocument) -> None:
    root = nid(doc, "root")
    new_id = doc.add_node(op_leaf("e"), root)
    assert view.node_count() == 8 and view.item(new_id).index_badge == 4
    doc.rename(new_id, "renamed")
    assert view.item(new_id).look.title == "renamed"
    doc.undo_stack.undo()
    assert view.item(new_id).look.title == "e"
    doc.remove_node(nid(doc, "pick"))
    assert view.node_count() == 5 and "a" not in titles(view)
    doc.undo_stack.undo()
    assert view.node_count() == 8 and "a" in titles(view)
    c = nid(doc, "c")
    doc.move_node(c, nid(doc, "pick"), 0)
    item_c, item_pick = view.item(c), view.item(nid(doc, "pick"))
    assert item_c.pos().y() > item_pick.pos().y() and item_c.index_badge == 1
    assert view.item(nid(doc, "a")).index_badge == 2
    doc.undo_stack.undo()
    assert view.item(c).index_badge == 2 and view.item(c).pos().y() == item_pick.pos().y()
    doc.undo_stack.undo()  # the add
    assert view.node_count() == 7


def test_collapse_hides_the_subtree_and_shows_the_count(
    view: CanvasView, doc: PlanDocument
) -> None:
    pick = nid(doc, "pick")
    c_before = view.item(nid(doc, "c")).pos().x()
    doc.set_collapsed(pick, True)
    assert not view.item(nid(doc, "a")).isVisible() and view.item(pick).hidden_count == 2
    assert view.item(nid(doc, "c")).pos().x() < c_before  # the freed room is used
    doc.undo_stack.undo()
    assert view.item(nid(doc, "a")).isVisible() and view.item(pick).hidden_count == 0
    assert view.item(nid(doc, "c")).pos().x() == c_before


def test_stored_positions_are_used_and_auto_layout_clears_them(
    view: CanvasView, doc: PlanDocument
) -> None:
    pick, a = nid(doc, "pick"), nid(doc, "a")
    auto_pick, auto_a = view.item(pick).pos(), view.item(a).pos()
    doc.set_layout({pick: NodeLayout(x=auto_pick.x() + 500, y=auto_pick.y() + 100)})
    assert view.item(pick).pos() == auto_pick + QPointF(500, 100)
    assert view.item(a).pos() == auto_a + QPointF(500, 100)  # children follow their parent
    view.action("auto_layout").trigger()
    assert view.item(pick).pos() == auto_pick and doc.plan.layout == {}
    doc.undo_stack.undo()
    assert view.item(pick).pos() == auto_pick + QPointF(500, 100)


def test_dragging_a_node_stores_its_position(view: CanvasView, doc: PlanDocument) -> None:
    c = nid(doc, "c")
    item = view.item(c)
    before = item.pos()
    item.setPos(before + QPointF(0, 300))  # as a mouse drag would, then the viewer reports it
    view.viewer.moved_nodes.emit({item: [before.x(), before.y()]})
    assert (doc.plan.layout[c].x, doc.plan.layout[c].y) == (before.x(), before.y() + 300)
    doc.undo_stack.undo()
    assert c not in doc.plan.layout and view.item(c).pos() == before


def test_dragging_a_node_onto_another_reparents_it(view: CanvasView, doc: PlanDocument) -> None:
    c, pick = nid(doc, "c"), nid(doc, "pick")
    item = view.item(c)
    before = item.pos()
    item.setPos(
        view.item(pick).mapToScene(view.item(pick).shape_rect().center())
        - item.shape_rect().center()
    )
    view.viewer.moved_nodes.emit({item: [before.x(), before.y()]})
    assert doc.locate(c)[0] == pick and doc.locate(c)[1] == 2
    assert view.item(c).pos().y() > view.item(pick).pos().y()
    doc.undo_stack.undo()
    assert doc.locate(c)[0] == nid(doc, "root") and view.item(c).pos() == before


def test_connecting_ports_reparents_and_refusals_restore_the_link(
    view: CanvasView, doc: PlanDocument, qtbot: QtBot
) -> None:
    c, pick, loop = nid(doc, "c"), nid(doc, "pick"), nid(doc, "loop")
    in_port = view.mirror.nodes[c].inputs()["parent"].view
    view.viewer.connection_changed.emit(
        [], [(view.mirror.nodes[pick].outputs()["children"].view, in_port)]
    )
    assert doc.locate(c)[0] == pick
    # The iterator already has its child: refused, with a message, and the drawn link stays.
    with qtbot.waitSignal(view.message) as blocker:
        view.viewer.connection_changed.emit(
            [], [(in_port, view.mirror.nodes[loop].outputs()["children"].view)]
        )
    assert "cannot take another child" in blocker.args[0]
    assert doc.locate(c)[0] == pick
    assert (
        len(in_port.connected_pipes) == 1 and in_port.connected_pipes[0].output_port.node.id == pick
    )


def test_delete_key_and_move_left_right_shortcuts(
    view: CanvasView, doc: PlanDocument, qtbot: QtBot
) -> None:
    c = nid(doc, "c")
    view.select(c)
    view.viewer.setFocus()
    view.activateWindow()
    qtbot.keyClick(view.viewer, Qt.Key.Key_Left, Qt.KeyboardModifier.ControlModifier)
    assert doc.locate(c)[1] == 0 and view.item(c).index_badge == 1
    qtbot.keyClick(view.viewer, Qt.Key.Key_Right, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClick(view.viewer, Qt.Key.Key_Right, Qt.KeyboardModifier.ControlModifier)
    assert doc.locate(c)[1] == 2
    with qtbot.waitSignal(view.message):
        qtbot.keyClick(view.viewer, Qt.Key.Key_Right, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClick(view.viewer, Qt.Key.Key_Delete)
    assert doc.plan.find(c) is None and view.node_count() == 6
    doc.undo_stack.undo()
    assert view.node_count() == 7


def test_copy_paste_duplicate_cut(view: CanvasView, doc: PlanDocument) -> None:
    pick, loop = nid(doc, "pick"), nid(doc, "loop")
    view.select(pick)
    view.action("copy").trigger()
    view.action("paste").trigger()  # as the selected node's last child
    assert len(doc.node(pick).children) == 3 and view.node_count() == 10
    view.action("duplicate").trigger()  # pick, now with 6 nodes
    assert view.node_count() == 16
    view.select(loop)
    view.action("cut").trigger()
    assert doc.plan.find(loop) is None and view.node_count() == 14
    assert "costar-subtree" in QApplication.clipboard().text()


def _drop(view: CanvasView, payload: dict[str, Any], scene_pos: QPointF) -> None:
    mime = QMimeData()
    mime.setData(PALETTE_MIME, json.dumps(payload).encode())
    pos = view.viewer.mapFromScene(scene_pos)
    event = QDropEvent(
        QPointF(pos),
        Qt.DropAction.CopyAction,
        mime,
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )
    view.viewer.dropEvent(event)


def test_palette_drop_on_a_node_adds_a_child_through_the_factory(
    view: CanvasView, doc: PlanDocument, qtbot: QtBot
) -> None:
    made: list[tuple[NodeKind, str | None]] = []

    def factory(kind: NodeKind, op: str | None) -> NodeSpec:
        made.append((kind, op))
        return op_leaf("dropped", op or "x")

    view.set_node_factory(factory)
    pick = nid(doc, "pick")
    centre = view.item(pick).mapToScene(view.item(pick).shape_rect().center())
    with qtbot.waitSignal(view.selection_changed) as selected:
        _drop(view, {"kind": "operation", "op": "gripper.close"}, centre)
    assert made == [(NodeKind.OPERATION, "gripper.close")]
    new = doc.node(pick).children[-1]
    assert new.name == "dropped" and selected.args == [[new.id]]
    # On a leaf: refused with a message; on empty canvas with a root: refused too.
    a = view.item(nid(doc, "a"))
    with qtbot.waitSignal(view.message):
        _drop(view, {"kind": "sequence", "op": None}, a.mapToScene(a.shape_rect().center()))
    with qtbot.waitSignal(view.message):
        _drop(view, {"kind": "sequence", "op": None}, QPointF(-5000, -5000))
    assert view.node_count() == 8


def test_palette_drop_on_an_empty_plan_adds_the_root(qtbot: QtBot, qapp: Any) -> None:
    document = PlanDocument()
    canvas = CanvasView(document)
    qtbot.addWidget(canvas)
    canvas.show()
    _drop(canvas, {"kind": "sequence", "op": None}, QPointF(0, 0))
    assert document.plan.tree is not None and document.plan.tree.kind is NodeKind.SEQUENCE
    assert canvas.node_count() == 1


def test_set_statuses_recolours_only_the_named_items(view: CanvasView, doc: PlanDocument) -> None:
    a, b = nid(doc, "a"), nid(doc, "b")
    view.set_statuses({a: Status.RUNNING, b: Status.FAILURE})
    assert view.status_of(a) is Status.RUNNING and view.status_of(b) is Status.FAILURE
    assert view.status_of(nid(doc, "c")) is None
    image = view.grab().toImage()
    item = view.item(a)
    point = view.viewer.mapFromScene(item.mapToScene(item.shape_rect().center() + QPointF(40, 8)))
    colour = image.pixelColor(view.viewer.mapTo(view, point))
    assert (colour.red(), colour.green(), colour.blue()) == STATUS_COLOURS[Status.RUNNING]
    view.clear_statuses()
    assert view.status_of(a) is None and view.status_of(b) is None


def test_a_failed_node_shows_its_error_type_in_its_tooltip(
    view: CanvasView, doc: PlanDocument
) -> None:
    b = nid(doc, "b")
    view.set_statuses({b: Status.FAILURE})
    view.set_failure_tips({b: "grasp_failed: the cup is not held"})
    assert view.item(b).toolTip().endswith("Failed: grasp_failed: the cup is not held")
    assert view.failure_tip(b) == "grasp_failed: the cup is not held"
    view.set_statuses({b: Status.RUNNING})  # tried again: the old failure goes
    assert view.failure_tip(b) == "" and "Failed" not in view.item(b).toolTip()
    view.set_failure_tips({b: "timeout: timed out after 2 s"})
    view.clear_statuses()
    assert view.failure_tip(b) == ""


def test_selection_signal_select_and_center_on(
    view: CanvasView, doc: PlanDocument, qtbot: QtBot
) -> None:
    c = nid(doc, "c")
    with qtbot.waitSignal(view.selection_changed) as blocker:
        view.select(c)
    assert blocker.args == [[c]] and view.selected_ids() == [c]
    view.center_on(nid(doc, "d"))
    d = view.item(nid(doc, "d"))
    centre = view.viewer.mapFromScene(d.mapToScene(d.shape_rect().center()))
    assert view.viewer.viewport().rect().contains(centre)
    with qtbot.waitSignal(view.selection_changed) as blocker:
        view.viewer.scene().clearSelection()
    assert blocker.args == [[]]


def test_mouse_click_selects_and_double_click_reports(
    view: CanvasView, doc: PlanDocument, qtbot: QtBot
) -> None:
    c = nid(doc, "c")
    item = view.item(c)
    view.center_on(c)
    pos = view.viewer.mapFromScene(item.mapToScene(QPointF(90, item.shape_rect().height() - 6)))
    with qtbot.waitSignal(view.selection_changed):
        qtbot.mouseClick(view.viewer.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert view.selected_ids() == [c]
    with qtbot.waitSignal(view.node_double_clicked) as blocker:
        qtbot.mouseDClick(view.viewer.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert blocker.args == [c]


def test_rename_through_the_title_editor(view: CanvasView, doc: PlanDocument, qtbot: QtBot) -> None:
    c = nid(doc, "c")
    item = view.item(c)
    item.start_rename()
    editor = item.text_item
    editor.setPlainText("place cup")
    editor.clearFocus()  # the end of editing reports the new name
    assert doc.node(c).name == "place cup" and view.item(c).look.title == "place cup"
    doc.undo_stack.undo()
    assert doc.node(c).name == "c"


def test_plan_reset_rebuilds(view: CanvasView, doc: PlanDocument) -> None:
    doc.new()
    assert view.node_count() == 0
    doc.load_text(_dump(build_plan(50)), None)
    assert view.node_count() == 50


def test_a_300_node_plan_opens(view: CanvasView, doc: PlanDocument, tmp_path: Any) -> None:
    from engine.files import save_plan

    path = tmp_path / "big.costar.json"
    save_plan(build_plan(300, seed=7), path)
    doc.open(path)
    assert view.node_count() == 300
    assert not view.grab().isNull()
    assert view.viewer.overview_mode  # fitted: the whole tree is in view, zoomed out


def test_actions_are_exposed_for_menus(view: CanvasView) -> None:
    names = {action.objectName() for action in view.actions()}
    assert {
        "canvas_delete",
        "canvas_copy",
        "canvas_cut",
        "canvas_paste",
        "canvas_duplicate",
        "canvas_move_left",
        "canvas_move_right",
        "canvas_auto_layout",
    } <= names
    assert view.action("move_left").shortcut().toString() == "Ctrl+Left"
    assert not view.action("delete").isEnabled()  # nothing selected


def test_context_menu_offers_the_node_commands(view: CanvasView, doc: PlanDocument) -> None:
    menu = view.commands.context_menu(nid(doc, "pick"), view)
    texts = [a.text() for a in menu.actions()]
    assert "Add child" in texts and "Delete" in texts and "Move left" in texts
    add_menu = next(a.menu() for a in menu.actions() if a.text() == "Add child")
    parallel = next(a for a in add_menu.actions() if a.text() == "Parallel")
    parallel.trigger()
    assert doc.node(nid(doc, "pick")).children[-1].kind is NodeKind.PARALLEL


def test_zoomed_out_links_are_one_overview_path(view: CanvasView, doc: PlanDocument) -> None:
    view.viewer.show_rect(QRectF(-20000, -20000, 40000, 40000))
    assert view.viewer.overview_mode
    new_id = doc.add_node(op_leaf("late"), nid(doc, "root"))
    ports = view.item(new_id).inputs
    assert ports and not any(port.isVisible() for port in ports)
    assert not view.grab().isNull()
    view.center_on(new_id)
    view.viewer.show_rect(view.item(new_id).sceneBoundingRect().adjusted(-300, -300, 300, 300))
    assert not view.viewer.overview_mode
    assert all(port.isVisible() for port in view.item(new_id).inputs)
    pipe = view.item(new_id).inputs[0].connected_pipes[0]
    assert pipe.isVisible()


def test_deleting_two_selected_siblings_is_one_step_that_puts_them_back(
    view: CanvasView, doc: PlanDocument
) -> None:
    before = doc.serialized()
    pick, c = nid(doc, "pick"), nid(doc, "c")
    view.item(pick).setSelected(True)
    view.item(c).setSelected(True)
    view.item(nid(doc, "a")).setSelected(True)  # inside pick: goes with it
    view.action("delete").trigger()
    assert doc.plan.find(pick) is None and doc.plan.find(c) is None
    assert doc.undo_stack.count() == 1 and doc.undo_stack.undoText() == "Delete nodes"
    doc.undo_stack.undo()
    assert doc.serialized() == before and view.node_count() == 7


def test_dragging_a_placed_node_onto_another_is_one_move_step(
    view: CanvasView, doc: PlanDocument
) -> None:
    c, pick = nid(doc, "c"), nid(doc, "pick")
    doc.set_layout({c: NodeLayout(400.0, 400.0)})
    before = doc.serialized()
    item = view.item(c)
    start = item.pos()
    item.setPos(
        view.item(pick).mapToScene(view.item(pick).shape_rect().center())
        - item.shape_rect().center()
    )
    view.viewer.moved_nodes.emit({item: [start.x(), start.y()]})
    assert doc.locate(c)[0] == pick and c not in doc.plan.layout  # placed automatically
    assert doc.undo_stack.undoText() == "Move c"
    after = doc.serialized()
    doc.undo_stack.undo()
    assert doc.serialized() == before and doc.plan.layout[c] == NodeLayout(400.0, 400.0)
    doc.undo_stack.redo()
    assert doc.serialized() == after


def test_a_skipped_node_has_its_own_colour(view: CanvasView, doc: PlanDocument) -> None:
    colours = {status: STATUS_COLOURS[status] for status in Status}
    assert len(set(colours.values())) == len(colours)  # every status its own colour
    a = nid(doc, "a")
    view.set_statuses({a: Status.SKIPPED})
    assert view.status_of(a) is Status.SKIPPED
    image = view.grab().toImage()
    item = view.item(a)
    point = view.viewer.mapFromScene(item.mapToScene(item.shape_rect().center() + QPointF(40, 8)))
    colour = image.pixelColor(view.viewer.mapTo(view, point))
    assert (colour.red(), colour.green(), colour.blue()) == STATUS_COLOURS[Status.SKIPPED]
