"""The inspector: one undo command per finished edit, undo restores the plan byte for byte."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QComboBox
from pytestqt.qtbot import QtBot

from capabilities.base import CapabilityRegistry
from engine.spec import Binding, NodeKind, NodeSpec, ParameterDecl
from engine.types import ParamType, Pose, Waypoint
from instructor_app.document import PlanDocument
from instructor_app.inspectors.base import EditorContext
from instructor_app.inspectors.editors import ChoiceEditor, NumberEditor, WaypointEditor
from instructor_app.inspectors.rows import MODE_REFERENCE, MODE_UNSET, MODE_VALUE
from instructor_app.panels.inspector import InspectorPanel


@pytest.fixture
def panel(
    qtbot: QtBot, document: PlanDocument, registry: CapabilityRegistry
) -> Iterator[InspectorPanel]:
    widget = InspectorPanel(document, registry)
    qtbot.addWidget(widget)
    yield widget


def _choose(combo: QComboBox, index: int) -> None:
    """What a user's pick in a combo box does."""
    combo.setCurrentIndex(index)
    combo.activated.emit(index)


def _undo_all_restores(document: PlanDocument, before: str) -> None:
    while document.undo_stack.canUndo():
        document.undo_stack.undo()
    assert document.serialized() == before


def test_nothing_shown_without_a_node(panel: InspectorPanel) -> None:
    assert panel.shown_node_id() is None and not panel.name_field.isEnabled()
    panel.show_node("no-such-node")
    assert panel.shown_node_id() is None


def test_rename_is_one_command(qtbot: QtBot, panel: InspectorPanel, document: PlanDocument) -> None:
    before = document.serialized()
    panel.show_node("move")
    assert panel.name_field.text() == "Go"
    panel.name_field.selectAll()
    qtbot.keyClicks(panel.name_field, "Go to cup")
    qtbot.keyClick(panel.name_field, Qt.Key.Key_Return)
    panel.name_field.editingFinished.emit()  # the focus leaving afterwards
    assert document.node("move").name == "Go to cup"
    assert document.undo_stack.count() == 1
    _undo_all_restores(document, before)
    assert panel.name_field.text() == "Go"


def test_typing_a_number_is_one_command(
    qtbot: QtBot, panel: InspectorPanel, document: PlanDocument
) -> None:
    before = document.serialized()
    panel.show_node("move")
    row = panel.port_row("ticks")
    assert row.mode == MODE_UNSET and "default: 3" in row.mode_combo.currentText()
    _choose(row.mode_combo, MODE_VALUE)
    assert document.node("move").params["ticks"] == Binding.fixed(3, ParamType.NUMBER)
    assert document.undo_stack.count() == 1
    assert isinstance(row.editor, NumberEditor)
    spin = row.editor.spin
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin, "123")
    assert document.undo_stack.count() == 1
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    assert document.node("move").params["ticks"] == Binding.fixed(123.0, ParamType.NUMBER)
    assert document.undo_stack.count() == 2
    _undo_all_restores(document, before)
    assert row.mode == MODE_UNSET


def test_fixed_reference_switch(
    panel: InspectorPanel, document: PlanDocument, qtbot: QtBot
) -> None:
    before = document.serialized()
    panel.show_node("move")
    row = panel.port_row("target")
    assert [row.type_combo.itemText(i) for i in range(row.type_combo.count())] == [
        "Pose",
        "Waypoint",
    ]
    _choose(row.mode_combo, MODE_REFERENCE)
    assert document.undo_stack.count() == 0  # no name yet: nothing to bind
    qtbot.keyClicks(row.ref_field, "OBJ_POSE")
    qtbot.keyClick(row.ref_field, Qt.Key.Key_Return)
    assert document.node("move").params["target"] == Binding.reference("OBJ_POSE")
    _choose(row.mode_combo, MODE_VALUE)
    assert document.node("move").params["target"] == Binding.fixed(Pose(), ParamType.POSE)
    _choose(row.mode_combo, MODE_REFERENCE)  # the name is remembered
    assert document.node("move").params["target"] == Binding.reference("OBJ_POSE")
    _choose(row.mode_combo, MODE_UNSET)
    assert "target" not in document.node("move").params
    assert document.undo_stack.count() == 4
    _undo_all_restores(document, before)


def test_type_switch_uses_the_plan_waypoints(panel: InspectorPanel, document: PlanDocument) -> None:
    waypoint = Waypoint("above_cup", pose=Pose((0.4, 0.0, 0.3)))
    document.store_waypoints([waypoint])
    before = document.serialized()
    count = document.undo_stack.count()
    panel.show_node("move")
    row = panel.port_row("target")
    _choose(row.mode_combo, MODE_VALUE)
    _choose(row.type_combo, 1)
    assert document.node("move").params["target"] == Binding.fixed(waypoint, ParamType.WAYPOINT)
    assert document.undo_stack.count() == count + 2
    document.undo_stack.undo()
    document.undo_stack.undo()
    assert document.serialized() == before


def test_output_name_and_completion(
    qtbot: QtBot, panel: InspectorPanel, document: PlanDocument
) -> None:
    before = document.serialized()
    document.declare_parameter(ParameterDecl("SPEED", ParamType.NUMBER, 1.0))
    panel.show_node("query")
    row = panel.port_row("result")
    qtbot.keyClicks(row.ref_field, "CUP_POSE")
    qtbot.keyClick(row.ref_field, Qt.Key.Key_Return)
    assert document.node("query").params["result"] == Binding.reference("CUP_POSE")
    assert document.undo_stack.count() == 2
    assert panel.completion_model().stringList() == ["CUP_POSE", "SPEED"]
    # The same model completes the input fields of another node.
    panel.show_node("move")
    completer = panel.port_row("target").ref_field.completer()
    assert completer.model().stringList() == ["CUP_POSE", "SPEED"]
    completer.setCompletionPrefix("cup")
    assert completer.currentCompletion() == "CUP_POSE"
    # Inputs that read a name do not add it: only writers do.
    document.set_param("move", "target", Binding.reference("NOBODY_WRITES"))
    assert "NOBODY_WRITES" not in panel.parameter_names()
    # Clearing the output name unbinds it.
    panel.show_node("query")
    row = panel.port_row("result")
    row.ref_field.clear()
    row.ref_field.editingFinished.emit()
    assert "result" not in document.node("query").params
    _undo_all_restores(document, before)


def test_logic_settings_are_port_rows_one_command_each(
    panel: InspectorPanel, document: PlanDocument
) -> None:
    before = document.serialized()
    panel.show_node("wait")
    row = panel.port_row("seconds")
    assert row.mode == MODE_VALUE and row.mode_combo.count() == 2  # no reference for settings
    assert row.editor is not None and row.editor.value() == 1.0
    row.editor.set_value(2.5)
    row.editor.value_committed.emit(2.5)
    assert document.node("wait").params == {"seconds": Binding.fixed(2.5, ParamType.DURATION)}
    root = document.add_node(NodeSpec(NodeKind.PARALLEL, id="par"), "root")
    panel.show_node(root)
    policy = panel.port_row("success")
    assert policy.mode == MODE_UNSET and "default: all" in policy.mode_combo.currentText()
    _choose(policy.type_combo, 1)
    _choose(policy.mode_combo, MODE_VALUE)
    assert policy.editor is not None
    policy.editor.value_committed.emit(2.0)
    assert document.node("par").params["success"] == Binding.fixed(2.0, ParamType.NUMBER)
    assert document.undo_stack.count() >= 3
    _undo_all_restores(document, before)


def test_follows_document_changes(panel: InspectorPanel, document: PlanDocument) -> None:
    panel.show_node("move")
    row = panel.port_row("ticks")
    document.set_param("move", "ticks", Binding.fixed(7.0, ParamType.NUMBER))
    assert row.mode == MODE_VALUE and row.editor.value() == 7.0
    assert panel.port_row("ticks") is row  # refreshed in place, not rebuilt
    document.undo_stack.undo()
    assert row.mode == MODE_UNSET
    document.rename("move", "Elsewhere")
    assert panel.name_field.text() == "Elsewhere"
    document.remove_node("move")
    assert panel.shown_node_id() is None
    document.undo_stack.undo()
    panel.show_node("move")
    document.new()
    assert panel.shown_node_id() is None


def test_object_names_reach_the_editors(
    panel: InspectorPanel, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    panel.set_object_names(["cup", "plate_4_holes"])
    panel.show_node("move")
    row = panel.port_row("target")
    assert row.editor is not None
    assert panel._context().object_names == ("cup", "plate_4_holes")
    # A node whose operation this cell lacks shows no rows and does not fail.
    document.add_node(NodeSpec(NodeKind.OPERATION, id="ghost", op="welding.weld"), "root")
    panel.show_node("ghost")
    assert "no such operation" in panel.doc_label.text()


def test_problems_are_marked_next_to_the_field(
    qtbot: QtBot, panel: InspectorPanel, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    from instructor_app.panels.validation import ValidationPanel

    validation = ValidationPanel(document, registry)
    qtbot.addWidget(validation)
    validation.problems_changed.connect(panel.set_problems)
    panel.show_node("move")
    validation.revalidate()
    assert "needs a value for 'target'" in panel.field_problem("target")
    assert panel.field_problem("ticks") == ""
    document.set_param("move", "target", Binding.fixed(Pose(), ParamType.POSE))
    with qtbot.waitSignal(validation.problems_changed):
        pass
    assert panel.field_problem("target") == ""


def test_the_parameter_area_grows_with_the_panel(qtbot: QtBot, panel: InspectorPanel) -> None:
    panel.show_node("move")
    panel.resize(360, 300)
    panel.show()
    qtbot.waitExposed(panel)
    qtbot.waitUntil(lambda: panel.parameter_area.height() > 0)
    small = panel.parameter_area.height()
    panel.resize(360, 900)
    qtbot.waitUntil(lambda: panel.parameter_area.height() >= small + 550)
    # Everything but the name field and the two labels above it is the parameter area.
    above = panel.parameter_area.geometry().top()
    assert panel.parameter_area.geometry().bottom() >= panel.height() - 10
    assert above < 200


def test_an_unset_port_shows_its_editor_and_a_value_entered_there_binds_it(
    qtbot: QtBot, panel: InspectorPanel, document: PlanDocument
) -> None:
    before = document.serialized()
    panel.show_node("move")
    row = panel.port_row("ticks")
    assert row.mode == MODE_UNSET and row.stack.currentWidget() is row.editor  # no "value" first
    assert isinstance(row.editor, NumberEditor) and row.editor.value() == 3  # its default
    spin = row.editor.spin
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin, "123")
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    assert document.node("move").params["ticks"] == Binding.fixed(123.0, ParamType.NUMBER)
    assert document.undo_stack.count() == 1 and row.mode == MODE_VALUE
    root = document.add_node(NodeSpec(NodeKind.PARALLEL, id="par"), "root")
    panel.show_node(root)
    policy = panel.port_row("success")
    assert policy.mode == MODE_UNSET and policy.stack.currentWidget() is policy.editor
    assert isinstance(policy.editor, ChoiceEditor) and policy.editor.value() == "all"
    _choose(policy.editor.combo, policy.editor.combo.currentIndex())  # the one shown: bound
    assert document.node("par").params["success"] == Binding.fixed("all", policy.value_type)
    assert policy.mode == MODE_VALUE
    _undo_all_restores(document, before)


def test_conditions_are_edited_in_the_advanced_section_one_command_each(
    qtbot: QtBot, panel: InspectorPanel, document: PlanDocument
) -> None:
    from engine.conditions import Condition

    before = document.serialized()
    panel.show()
    panel.show_node("move")
    assert not panel.advanced.isVisible()  # closed for a node without conditions
    qtbot.mouseClick(panel.advanced_toggle, Qt.MouseButton.LeftButton)
    assert panel.advanced.isVisible()
    field = panel.condition_fields[Condition.SKIP_IF]
    qtbot.keyClicks(field, "count >= 3")
    assert document.undo_stack.count() == 0
    qtbot.keyClick(field, Qt.Key.Key_Return)
    field.editingFinished.emit()  # the focus leaving afterwards: no second step
    assert document.node("move").conditions == {Condition.SKIP_IF: "count >= 3"}
    assert document.undo_stack.count() == 1
    post = panel.condition_fields[Condition.ON_HALTED]
    qtbot.keyClicks(post, "halted := true")
    qtbot.keyClick(post, Qt.Key.Key_Return)
    assert document.undo_stack.count() == 2
    # another node: empty fields, closed; back: the scripts, opened by themselves
    panel.show_node("wait")
    assert field.text() == "" and not panel.advanced.isVisible()
    panel.show_node("move")
    assert panel.advanced.isVisible() and field.text() == "count >= 3"
    # clearing a field removes the condition
    field.clear()
    qtbot.keyClick(field, Qt.Key.Key_Return)
    assert Condition.SKIP_IF not in document.node("move").conditions
    document.undo_stack.undo()
    assert field.text() == "count >= 3"  # the panel follows the document
    _undo_all_restores(document, before)
    assert field.text() == "" and document.node("move").conditions == {}


def test_a_condition_problem_is_marked_on_its_field(
    panel: InspectorPanel, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    from engine.conditions import Condition
    from engine.validation import validate_plan

    panel.show_node("move")
    document.set_condition("move", Condition.WHILE, "ready ==")
    panel.set_problems(validate_plan(document.plan, registry))
    assert "while condition of 'Go' is not a script" in panel.field_problem("while")
    assert "line 1, column" in panel.field_problem("while")


def test_an_unset_waypoint_asks_for_a_choice_and_the_first_one_chosen_binds_it(
    qtbot: QtBot,
) -> None:
    """Not the plan's first waypoint shown as if chosen: a blank that asks for one."""
    first = Waypoint("above_cup", pose=Pose((0.4, 0.0, 0.3)))
    second = Waypoint("over_bin", pose=Pose((0.5, -0.2, 0.3)))
    editor = WaypointEditor()
    qtbot.addWidget(editor)
    editor.show_unset()
    editor.set_context(EditorContext(waypoints=(first, second)))
    assert editor.combo.currentIndex() == -1 and editor.combo.currentText() == ""
    assert editor.combo.placeholderText() == "choose a waypoint"
    with qtbot.waitSignal(editor.value_committed) as committed:
        _choose(editor.combo, 0)
    assert committed.args == [first]
    editor.set_context(EditorContext(waypoints=(first, second)))  # bound: shown as chosen
    assert editor.combo.currentText().startswith("above_cup")


def test_settings_of_btcpp_builtins_edit_as_their_words(
    panel: InspectorPanel, document: PlanDocument
) -> None:
    before = document.serialized()
    once = document.add_node(NodeSpec(NodeKind.RUN_ONCE, id="once"), "root")
    panel.show_node(once)
    row = panel.port_row("then_skip")
    assert row.mode == MODE_UNSET and isinstance(row.editor, ChoiceEditor)
    assert row.editor.value() == "true"
    _choose(row.editor.combo, row.editor.combo.findText("false"))
    assert document.node("once").params["then_skip"] == Binding.fixed("false", ParamType.TEXT)
    guard = document.add_node(NodeSpec(NodeKind.PRECONDITION, id="guard"), "root")
    panel.show_node(guard)
    otherwise = panel.port_row("else")
    assert isinstance(otherwise.editor, ChoiceEditor) and otherwise.editor.value() == "FAILURE"
    _choose(otherwise.editor.combo, otherwise.editor.combo.findText("SKIPPED"))
    assert document.node("guard").params["else"] == Binding.fixed("SKIPPED", ParamType.TEXT)
    _undo_all_restores(document, before)
