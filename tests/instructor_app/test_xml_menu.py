"""File > Export / Import BehaviorTree.CPP XML, through the menu actions and a patched
file dialog.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from gui_driver import ScriptedDialogs, make_window
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QFileDialog

from engine.files import dump_plan, load_plan
from instructor_app.main_window import MainWindow


def _menu_action(window: MainWindow, text: str) -> QAction:
    """The File menu's action whose text (without the & mnemonics) is ``text``."""
    files = next(a.menu() for a in window.menuBar().actions() if a.text() == "&File")
    return next(a for a in files.actions() if a.text().replace("&", "") == text)


def _patch_dialogs(monkeypatch: pytest.MonkeyPatch, answer: str) -> list[tuple[str, str]]:
    asked: list[tuple[str, str]] = []

    def dialog(parent: Any, title: str, folder: str, filters: str) -> tuple[str, str]:
        asked.append((title, folder))
        return answer, filters.split(";;")[0]

    monkeypatch.setattr(QFileDialog, "getSaveFileName", staticmethod(dialog))
    monkeypatch.setattr(QFileDialog, "getOpenFileName", staticmethod(dialog))
    return asked


def test_export_then_import_through_the_file_menu(
    qtbot: Any, none_session: Any, tmp_path: Path, figure3_path: Path, monkeypatch: Any
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    assert window.open_plan(figure3_path)
    target = tmp_path / "figure3"  # the suffix is added
    asked = _patch_dialogs(monkeypatch, str(target))
    _menu_action(window, "Export BehaviorTree.CPP XML…").trigger()
    exported = tmp_path / "figure3.xml"
    assert exported.exists() and dialogs.errors == []
    assert asked[0][1].endswith("figure3_debug.xml")  # suggested from the plan's file
    assert 'main_tree_to_execute="' in exported.read_text(encoding="utf-8")

    window.document.new()
    _patch_dialogs(monkeypatch, str(exported))
    _menu_action(window, "Import BehaviorTree.CPP XML…").trigger()
    qtbot.waitUntil(lambda: window.document.plan.tree is not None)
    assert dialogs.errors == []
    assert dump_plan(window.document.plan) == dump_plan(load_plan(figure3_path))
    assert window.document.path is None and window.document.dirty  # a new plan, not saved
    assert window.views.canvas.isVisible()


def test_an_import_with_unknown_nodes_shows_every_line_and_keeps_the_plan(
    qtbot: Any, none_session: Any, tmp_path: Path, figure3_path: Path, monkeypatch: Any
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    assert window.open_plan(figure3_path)
    before = dump_plan(window.document.plan)
    foreign = tmp_path / "foreign.xml"
    foreign.write_text(
        '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Sequence>\n<OpenDoor/>\n'
        "<CloseDoor/>\n</Sequence>\n</BehaviorTree>\n</root>\n",
        encoding="utf-8",
    )
    _patch_dialogs(monkeypatch, str(foreign))
    _menu_action(window, "Import BehaviorTree.CPP XML…").trigger()
    assert [title for title, _ in dialogs.errors] == ["Cannot import the XML"]
    text = dialogs.errors[0][1]
    assert f"{foreign}: line 4:" in text and "'OpenDoor'" in text
    assert f"{foreign}: line 5:" in text and "'CloseDoor'" in text
    assert dump_plan(window.document.plan) == before
    assert window.document.path == figure3_path


def test_a_cancelled_export_writes_nothing(
    qtbot: Any, none_session: Any, tmp_path: Path, figure3_path: Path, monkeypatch: Any
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    assert window.open_plan(figure3_path)
    _patch_dialogs(monkeypatch, "")
    _menu_action(window, "Export BehaviorTree.CPP XML…").trigger()
    assert list(tmp_path.glob("*.xml")) == [] and dialogs.errors == []
