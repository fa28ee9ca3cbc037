"""MainWindow: files and their questions, palette -> document, selection, runs, recovery."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtWidgets import QMessageBox

from engine.files import dump_plan
from engine.status import Status
from instructor_app.main_window import Dialogs, MainWindow
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import (
    ScriptedDialogs,
    add_from_palette,
    make_window,
    node_named,
    rename,
    run_to_end,
    select,
)
from tests.instructor_app.runtime.plans import endless_plan, failing_plan


@pytest.fixture
def dialogs() -> ScriptedDialogs:
    return ScriptedDialogs()


@pytest.fixture
def window(
    qtbot: Any, none_session: CellSession, tmp_path: Path, dialogs: ScriptedDialogs
) -> MainWindow:
    return make_window(qtbot, none_session, tmp_path, dialogs)


def write_plan(path: Path, plan: Any) -> Path:
    path.write_text(dump_plan(plan), encoding="utf-8")
    return path


# ---------------------------------------------------------------------- files


def test_the_title_names_the_file_and_marks_unsaved_changes(
    qtbot: Any, window: MainWindow, figure3_path: Path, tmp_path: Path
) -> None:
    assert window.windowTitle() == "Untitled plan — CoSTAR Instructor"
    assert window.open_plan(figure3_path)
    assert window.windowTitle() == "figure3_debug.costar.json — CoSTAR Instructor"
    rename(qtbot, window, node_named(window, "transfer"), "carry")
    assert window.windowTitle() == "figure3_debug.costar.json* — CoSTAR Instructor"
    window.document.save(tmp_path / "copy.costar.json")
    assert window.windowTitle() == "copy.costar.json — CoSTAR Instructor"


def test_a_corrupt_file_shows_an_error_and_keeps_the_document(
    window: MainWindow, figure3_path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    window.dialogs = Dialogs()  # the real dialogs, with QMessageBox.critical patched
    shown: list[str] = []
    monkeypatch.setattr(QMessageBox, "critical", lambda parent, title, text: shown.append(text))
    window.open_plan(figure3_path)
    before = window.document.serialized()
    corrupt = tmp_path / "broken.costar.json"
    corrupt.write_text('{"format": "costar-plan", "tree": [1, 2', encoding="utf-8")
    assert window.open_plan(corrupt) is False
    assert len(shown) == 1 and "broken.costar.json" in shown[0]
    assert window.document.serialized() == before and window.document.path == figure3_path
    assert str(corrupt.resolve()) not in window.settings.recent_files()


def test_closing_with_unsaved_changes_asks_and_cancel_keeps_the_window(
    qtbot: Any, window: MainWindow, dialogs: ScriptedDialogs, figure3_path: Path
) -> None:
    window.open_plan(figure3_path)
    rename(qtbot, window, node_named(window, "transfer"), "carry")
    dialogs.save_answers = ["cancel"]
    assert window.close() is False and window.isVisible()
    assert dialogs.asked == [("save", "figure3_debug.costar.json")]
    dialogs.save_answers = ["discard"]
    assert window.close() is True
    assert not window.autosaver.plan_file.exists()


def test_save_from_the_close_question_writes_the_file(
    qtbot: Any, window: MainWindow, dialogs: ScriptedDialogs, tmp_path: Path
) -> None:
    add_from_palette(qtbot, window, "sequence")
    target = tmp_path / "new plan"
    dialogs.save_answers, dialogs.save_paths = ["save"], [str(target)]
    assert window.close() is True
    saved = tmp_path / "new plan.costar.json"
    assert saved.exists() and '"kind": "sequence"' in saved.read_text(encoding="utf-8")
    assert window.settings.recent_files() == [str(saved.resolve())]


def test_the_real_question_box_answers_through_its_buttons(
    window: MainWindow, monkeypatch: pytest.MonkeyPatch
) -> None:
    buttons = QMessageBox.StandardButton
    made: list[QMessageBox] = []

    class Box(QMessageBox):
        def exec(self) -> int:
            made.append(self)
            return int(buttons.Cancel.value)

    monkeypatch.setattr(Dialogs, "make_box", lambda self, parent: Box(parent))
    assert Dialogs().ask_save_changes(window, "plan") == "cancel"
    wanted = buttons.Save | buttons.Discard | buttons.Cancel
    assert made[0].standardButtons() == wanted and "plan" in made[0].text()


def test_new_and_open_ask_before_dropping_changes(
    qtbot: Any, window: MainWindow, dialogs: ScriptedDialogs, figure3_path: Path
) -> None:
    add_from_palette(qtbot, window, "sequence")
    edited = window.document.serialized()
    dialogs.save_answers = ["cancel", "cancel"]
    window.actions_by_name["new"].trigger()
    assert window.open_plan(figure3_path) is False
    assert window.document.serialized() == edited and len(dialogs.asked) == 2
    dialogs.save_answers = ["discard"]
    window.actions_by_name["new"].trigger()
    assert window.document.plan.tree is None and not window.document.dirty


def test_recent_files_are_remembered_and_reopen(window: MainWindow, figure3_path: Path) -> None:
    window.open_plan(figure3_path)
    window.actions_by_name["new"].trigger()
    window.recent_menu.rebuild()
    first = window.recent_menu.actions()[0]
    assert first.data() == str(figure3_path.resolve())
    first.trigger()
    assert window.document.path == figure3_path.resolve()


# ---------------------------------------------------------------------- editing


def test_palette_items_go_under_the_selected_node(qtbot: Any, window: MainWindow) -> None:
    root = add_from_palette(qtbot, window, "sequence")
    assert window.document.plan.tree.id == root
    select(window, root)
    leaf = add_from_palette(qtbot, window, "debug.succeed")
    assert window.document.locate(leaf)[:2] == (root, 0)
    assert window.views.canvas.selected_ids() == [leaf]  # the new node is selected
    # the leaf is selected: the next node goes right after it, as a sibling
    sibling = add_from_palette(qtbot, window, "sequence")
    assert window.document.locate(sibling)[:2] == (root, 1)


def test_an_unavailable_operation_is_not_added(qtbot: Any, window: MainWindow) -> None:
    add_from_palette(qtbot, window, "sequence")
    item = next(i for i in window.views.palette.items() if not i.available)
    assert window.add_palette_item(item) is None
    assert "cannot be used" in window.statusBar().currentMessage()


def test_selecting_shows_the_node_and_problems_select_on_the_canvas(
    qtbot: Any, window: MainWindow
) -> None:
    root = add_from_palette(qtbot, window, "sequence")
    select(window, root)
    log_node = add_from_palette(qtbot, window, "debug.log")  # its message is required
    window.views.validation.revalidate()
    select(window, root)
    problems = window.views.validation.list
    row = next(
        problems.topLevelItem(i)
        for i in range(problems.topLevelItemCount())
        if "message" in problems.topLevelItem(i).text(2)
    )
    problems.setCurrentItem(row)
    assert window.views.canvas.selected_ids() == [log_node]
    assert window.views.inspector.shown_node_id() == log_node
    assert "error" in window.problems_label.text()


def test_undo_and_redo_actions_edit_the_document(qtbot: Any, window: MainWindow) -> None:
    add_from_palette(qtbot, window, "sequence")
    window.actions_by_name["undo"].trigger()
    assert window.document.plan.tree is None
    window.actions_by_name["redo"].trigger()
    assert window.document.plan.tree is not None
    keys = [k.toString() for k in window.actions_by_name["redo"].shortcuts()]
    assert keys == ["Ctrl+Shift+Z", "Ctrl+Y"]


# ---------------------------------------------------------------------- runs


def test_a_run_colours_the_canvas_and_fills_the_panels(
    qtbot: Any, window: MainWindow, figure3_path: Path
) -> None:
    window.open_plan(figure3_path)
    outcome = run_to_end(qtbot, window)
    assert outcome.status is Status.SUCCESS
    canvas = window.views.canvas
    assert canvas.status_of(window.document.plan.tree.id) is Status.SUCCESS
    assert canvas.status_of(node_named(window, "release")) is Status.SUCCESS
    assert {"CUP_POSE", "BIN_POSE"} <= set(window.views.blackboard.values())
    assert any("closing the gripper" in line for line in window.views.log.lines())
    assert window.running_panel.count() == 0 and window.failure_button.isHidden()
    assert window.run_actions.run.isEnabled() and not window.run_actions.stop.isEnabled()
    assert "SUCCESS" in window.statusBar().currentMessage()


def test_a_failure_is_shown_and_clicking_it_selects_the_node(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    window.open_plan(write_plan(tmp_path / "failing.costar.json", failing_plan()))
    outcome = run_to_end(qtbot, window)
    leaf = node_named(window, "look for cup")
    assert outcome.failed_node == leaf
    button = window.failure_button
    assert button.isVisible() and button.text() == "look for cup failed: no cup"
    assert "passed up by Sequence 'inner', Sequence 'top'" in button.toolTip()
    button.click()
    assert window.views.canvas.selected_ids() == [leaf]


def test_stop_ends_a_run_and_the_running_list_follows_it(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    window.open_plan(write_plan(tmp_path / "endless.costar.json", endless_plan()))
    window.run_actions.run.trigger()
    assert not window.cell_combo.isEnabled() and window.run_actions.stop.isEnabled()
    qtbot.waitUntil(lambda: window.running_panel.count() == 2, timeout=5000)
    assert window.running_panel.item(1).text().endswith("slow[0]")
    with qtbot.waitSignal(window.controller.run_finished, timeout=5000) as blocker:
        window.run_actions.stop.trigger()
    assert blocker.args[0].event.reason == "stopped"
    assert window.running_panel.count() == 0 and window.cell_combo.isEnabled()


def test_an_invalid_plan_is_not_started_and_says_why(window: MainWindow, qtbot: Any) -> None:
    with qtbot.waitSignal(window.controller.run_refused, timeout=2000):
        window.run_actions.run.trigger()
    assert "not started" in window.statusBar().currentMessage()
    assert any("empty" in line for line in window.views.log.lines())


# ---------------------------------------------------------------------- recovery


def test_a_crashed_session_is_offered_and_restored(
    qtbot: Any, none_session: CellSession, tmp_path: Path, figure3_path: Path
) -> None:
    first = make_window(qtbot, none_session, tmp_path, autosave_ms=20)
    first.open_plan(figure3_path)
    rename(qtbot, first, node_named(first, "transfer"), "edited before the crash")
    with qtbot.waitSignal(first.autosaver.written, timeout=3000):
        pass
    edited = first.document.serialized()
    # The first window "dies" (no clean close); a new one starts with the same folder.
    dialogs = ScriptedDialogs()
    dialogs.restore_answers = [True]
    second = make_window(qtbot, none_session, tmp_path, dialogs)
    assert second.offer_recoveries() is True
    assert [kind for kind, _ in dialogs.asked] == ["restore"]
    assert second.document.serialized() == edited and second.document.dirty
    assert second.document.path == figure3_path
    assert second.windowTitle().startswith("figure3_debug.costar.json*")
    node_id = node_named(second, "edited before the crash")
    assert second.document.node(node_id).name == "edited before the crash"


def test_an_operator_question_of_the_run_is_answered_in_the_window(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    from PySide6.QtCore import Qt

    from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
    from engine.types import ParamType

    ask = NodeSpec(NodeKind.OPERATION, "ask", op="collaboration.confirm",
                   params={"prompt": Binding.fixed("Is the bin in place?", ParamType.TEXT)})  # fmt: skip
    window.open_plan(write_plan(tmp_path / "ask.costar.json", PlanSpec(ask, "ask")))
    panel = window.operator_panel
    with qtbot.waitSignal(panel.prompt_shown, timeout=10_000):
        window.run_actions.run.trigger()
    assert window.docks["operator"].isVisible()
    row = panel.rows()[0]
    assert row.text_label.text() == "Is the bin in place?"
    with qtbot.waitSignal(window.controller.run_finished, timeout=10_000) as finished:
        qtbot.mouseClick(row.yes_button, Qt.MouseButton.LeftButton)
    assert finished.args[0].status is Status.SUCCESS
