"""Small things of the first hour: the About box shows the version, a recovered shipped
example is saved elsewhere (Save As), no stale modifier hint stays on the canvas.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from engine.files import load_plan
from instructor_app.runtime.session import CellSession
from tests.instructor_app.conftest import EXAMPLES
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window, search_insert


def test_about_shows_the_package_version(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    window.actions_by_name["about"].trigger()
    kind, text = dialogs.asked[-1]
    assert kind == "about" and metadata.version("costar-instructor") in text


def test_a_recovered_example_is_saved_as_a_new_file(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    example = EXAMPLES / "figure3_debug.costar.json"
    shipped = example.read_text(encoding="utf-8")
    # what crash recovery does: the autosaved text, with the file it came from
    window.document.load_text(shipped, example)
    assert window.document.dirty
    target = tmp_path / "my figure3"
    dialogs.save_paths = [str(target)]
    window.actions_by_name["save"].trigger()
    assert dialogs.save_paths == []  # the save asked for a location
    assert window.document.path == tmp_path / "my figure3.costar.json"
    assert example.read_text(encoding="utf-8") == shipped


def test_ctrl_leaves_no_hint_on_the_canvas(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    viewer = window.views.canvas.viewer
    qtbot.keyPress(viewer, Qt.Key.Key_Control, Qt.KeyboardModifier.ControlModifier)
    hint = viewer._cursor_text  # NodeGraphQt's overlay; the one way to see it drawn
    assert not hint.isVisible()


def test_a_new_empty_plan_is_no_error_but_a_hint(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.new_plan()
    window.views.validation.revalidate()
    text = window.problems_label.text()
    assert "error" not in text.lower() and "add a node" in text.lower(), text
    assert window.views.validation.list.topLevelItemCount() == 0
    window.run_actions.run.trigger()  # a run is still refused, and says why
    assert any("empty" in line for line in window.views.log.lines())


def test_save_as_names_an_unnamed_plan_after_its_file(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    window.new_plan()
    search_insert(qtbot, window, "succeed", "debug.succeed")
    dialogs.save_paths = [str(tmp_path / "pick cups.costar.json")]
    assert window.files.save_plan_as()
    assert window.document.plan.name == "pick cups" and not window.document.dirty
    assert load_plan(tmp_path / "pick cups.costar.json").name == "pick cups"
    window.document.rename_plan("My plan")  # a name the user gave stays
    dialogs.save_paths = [str(tmp_path / "other.costar.json")]
    assert window.files.save_plan_as()
    assert window.document.plan.name == "My plan"


def test_paste_as_child_needs_a_node_that_takes_one(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    paste = window.views.canvas.commands.actions["paste"]
    window.new_plan()
    assert paste.isEnabled()  # an empty plan: the pasted nodes become the plan
    root = search_insert(qtbot, window, "sequence", "sequence")
    leaf = search_insert(qtbot, window, "succeed", "debug.succeed")
    window.views.canvas.select(root)
    assert paste.isEnabled()
    window.views.canvas.select(leaf)
    assert not paste.isEnabled()  # a leaf takes no child
    window.views.canvas.viewer.scene().clearSelection()  # as a click on the empty canvas
    assert window.views.canvas.selected_ids() == [] and not paste.isEnabled()
