"""Named parameters while paused: the run is paused before a move, the worker changes the
move's target in the Blackboard panel (double-click, type it in mm and degrees, Enter), and
the run goes on with it; a bad value is refused with a message; Ctrl+Z undoes the change
while still paused; each entry shows the node that wrote it and the tick.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QAbstractItemView, QLineEdit, QTreeWidgetItem

from engine.files import dump_plan
from engine.spec import (
    Binding,
    NodeKind,
    NodeSpec,
    ParameterDecl,
    PlanSpec,
    SubtreePort,
    SubtreeSpec,
)
from engine.status import Status
from engine.types import ParamType, Pose
from instructor_app.main_window import MainWindow
from instructor_app.panels.blackboard import TICK, VALUE, WRITER
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import click_node, make_window, show_tab
from tests.instructor_app.runtime.plans import number, op

FOUND = Pose((0.4, 0.0, 0.3), (1.0, 0.0, 0.0, 0.0))
FOUND_TEXT = "(400.0, 0.0, 300.0) mm, rpy (180.0, 0.0, 0.0)°"
TYPED = "(500, 100, 250) mm, rpy (180, 0, 90)°"


def _plan() -> PlanSpec:
    """A query finds the target, a wait, then a move to the target."""
    steps = [
        op(
            "debug.query",
            "find target",
            value=Binding.fixed(FOUND, ParamType.POSE),
            result=Binding.reference("TARGET"),
        ),
        op("debug.running", "settle", ticks=number(2)),
        op("debug.pretend_move", "move", target=Binding.reference("TARGET"), ticks=number(1)),
    ]
    return PlanSpec(
        tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=steps),
        name="move to target",
        parameters=[ParameterDecl("TARGET", ParamType.POSE, Pose())],
    )


def _window(qtbot: Any, session: CellSession, folder: Path) -> MainWindow:
    window = make_window(qtbot, session, folder)
    window.document.load_text(dump_plan(_plan()), None)
    show_tab(qtbot, window, "Blackboard")
    return window


def _edit(qtbot: Any, window: MainWindow, key: str, text: str) -> None:
    """Double-click the value of ``key``, type ``text`` over it and press Enter."""
    panel = window.views.blackboard
    item: QTreeWidgetItem = panel.item(key)
    panel.tree.scrollToItem(item)
    rect = panel.tree.visualItemRect(item)
    x = panel.tree.header().sectionViewportPosition(VALUE) + 10
    pos = rect.center()
    pos.setX(x)
    qtbot.mouseClick(panel.tree.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    qtbot.mouseDClick(panel.tree.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    qtbot.waitUntil(lambda: isinstance(panel.tree.focusWidget(), QLineEdit), timeout=2000)
    editor = panel.tree.focusWidget()
    assert isinstance(editor, QLineEdit)
    editor.selectAll()
    qtbot.keyClicks(editor, text)
    qtbot.keyClick(editor, Qt.Key.Key_Return)
    editing = QAbstractItemView.State.EditingState
    qtbot.waitUntil(lambda: panel.tree.state() != editing, timeout=2000)


def test_a_target_changed_while_paused_is_where_the_move_goes(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = _window(qtbot, none_session, tmp_path)
    panel, controller = window.views.blackboard, window.controller
    plan_edits = window.document.undo_stack.count()
    window.run_actions.step.trigger()  # one tick: the target is found, the move is next
    qtbot.waitUntil(lambda: panel.values().get("TARGET") == FOUND, timeout=5000)
    assert controller.state == "paused" and panel.editable
    assert panel.text_of("TARGET") == FOUND_TEXT
    assert (panel.text_of("TARGET", WRITER), panel.text_of("TARGET", TICK)) == ("find target", "1")

    _edit(qtbot, window, "TARGET", "somewhere over there")
    assert "TARGET holds a Pose" in panel.message.text()
    assert panel.message.property("error") is True
    assert panel.text_of("TARGET") == FOUND_TEXT and window.blackboard_edits.stack.count() == 0

    _edit(qtbot, window, "TARGET", TYPED)
    qtbot.waitUntil(lambda: panel.text_of("TARGET", WRITER) == "you (while paused)", timeout=5000)
    assert panel.text_of("TARGET") == "(500.0, 100.0, 250.0) mm, rpy (180.0, 0.0, 90.0)°"
    assert panel.text_of("TARGET", TICK) == "1"  # set between ticks: no tick for it
    assert window.actions_by_name["undo"].text() == f"&Undo Set TARGET to {panel.text_of('TARGET')}"

    qtbot.keyClick(panel.tree, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # undo
    qtbot.waitUntil(lambda: panel.text_of("TARGET") == FOUND_TEXT, timeout=5000)
    assert controller.state == "paused"
    assert window.document.undo_stack.count() == plan_edits  # the plan did not change
    window.actions_by_name["redo"].trigger()
    qtbot.waitUntil(lambda: panel.text_of("TARGET") != FOUND_TEXT, timeout=5000)

    with qtbot.waitSignal(controller.run_finished, timeout=10000) as finished:
        window.run_actions.run.trigger()  # go on
    assert finished.args[0].status is Status.SUCCESS
    moves = [line for line in window.views.log.lines() if "moving to" in line]
    assert len(moves) == 1 and "position=(0.5, 0.1, 0.25)" in moves[0]
    assert not panel.editable and window.blackboard_edits.stack.count() == 0
    window.actions_by_name["undo"].trigger()  # the plan's stack again: nothing to undo
    assert panel.text_of("TARGET").startswith("(500.0, 100.0, 250.0)")


def _instance_plan() -> PlanSpec:
    """An instance of Pick: a private PICKED, an output RESULT, a shared name SEEN."""
    inside = NodeSpec(
        NodeKind.SEQUENCE,
        name="Pick",
        children=[
            op("debug.query", "find", value=Binding.reference("OBJECT"), result=ref("PICKED")),
            set_param("keep", ref("PICKED"), "RESULT"),
            set_param("count", number(1), "SEEN"),
        ],
    )
    pick = SubtreeSpec(
        id="test.pick",
        name="Pick",
        tree=inside,
        inputs=[SubtreePort("OBJECT", ParamType.TEXT, "what to pick")],
        outputs=[SubtreePort("RESULT", ParamType.ANY, "what was picked")],
        shared_names=["SEEN"],
    )
    instance = NodeSpec(
        NodeKind.SUBTREE,
        name="Pick cup",
        subtree=pick.ref,
        params={"OBJECT": Binding.fixed("cup", ParamType.TEXT), "RESULT": ref("GOT")},
    )
    top = NodeSpec(NodeKind.SEQUENCE, name="top", children=[instance])
    return PlanSpec(tree=top, name="pick", subtrees=[pick])


def ref(name: str) -> Binding:
    return Binding.reference(name)


def set_param(label: str, value: Binding, name: str) -> NodeSpec:
    params = {"value": value, "name": ref(name)}
    return NodeSpec(NodeKind.OPERATION, name=label, op="debug.set_param", params=params)


def test_each_scope_shows_its_names_and_the_nodes_that_wrote_them(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_instance_plan()), None)
    panel = window.views.blackboard
    with qtbot.waitSignal(window.controller.run_finished, timeout=10000) as finished:
        window.run_actions.run.trigger()
    assert finished.args[0].status is Status.SUCCESS
    qtbot.waitUntil(lambda: "GOT" in panel.values(), timeout=5000)
    assert panel.scopes() == ["Plan", "Shared names", "Pick cup"]
    picked = next(key for key in panel.values() if key.endswith("/PICKED"))
    assert panel.item(picked).parent().text(0) == "Pick cup"
    assert panel.text_of(picked) == "cup"
    assert panel.text_of(picked, WRITER) == "Pick cup > find"
    assert panel.item("SEEN").parent().text(0) == "Shared names"
    assert panel.text_of("SEEN", WRITER) == "Pick cup > count"
    assert panel.text_of("GOT", WRITER) == "Pick cup"  # copied out by the instance
    assert not panel.editable  # the run is over


def test_at_a_breakpoint_before_the_move_a_changed_target_is_where_it_goes(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    """The issue's check: F9 on the move, Run; paused there, the worker types a new target
    in the Blackboard panel; Continue, and the move goes to the new target.
    """
    window = _window(qtbot, none_session, tmp_path)
    panel, controller = window.views.blackboard, window.controller
    move = next(n.id for _, n in window.document.plan.walk() if n.name == "move")
    window.activateWindow()  # the shortcuts are the window's
    qtbot.waitUntil(window.isActiveWindow)
    click_node(qtbot, window, move)
    qtbot.keyClick(window.views.canvas.viewer, Qt.Key.Key_F9)
    with qtbot.waitSignal(controller.run_paused, timeout=10000) as paused:
        window.run_actions.run.trigger()
    assert paused.args[0] == move
    qtbot.waitUntil(lambda: panel.values().get("TARGET") == FOUND and panel.editable, timeout=5000)

    _edit(qtbot, window, "TARGET", TYPED)
    qtbot.waitUntil(lambda: panel.text_of("TARGET", WRITER) == "you (while paused)", timeout=5000)
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as finished:
        window.run_actions.run.trigger()  # continue
    assert finished.args[0].status is Status.SUCCESS
    moves = [line for line in window.views.log.lines() if "moving to" in line]
    assert len(moves) == 1 and "position=(0.5, 0.1, 0.25)" in moves[0]
