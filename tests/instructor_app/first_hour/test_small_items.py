"""Small things of the first hour: the About box shows the version, a recovered shipped
example is saved elsewhere (Save As), no stale modifier hint stays on the canvas.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from instructor_app.runtime.session import CellSession
from tests.instructor_app.conftest import EXAMPLES
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window


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
