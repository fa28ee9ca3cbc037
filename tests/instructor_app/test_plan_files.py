"""PlanFiles on its own: a document, scripted dialogs and settings, no MainWindow."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtWidgets import QWidget

from instructor_app.document.autosave import Autosaver
from instructor_app.document.editing import PlanDocument
from instructor_app.plan_files import PlanFiles
from instructor_app.settings import AppSettings
from tests.instructor_app.gui_driver import ScriptedDialogs


class Harness:
    def __init__(self, qtbot: Any, settings: AppSettings, recovery_dir: Path) -> None:
        self.window = QWidget()
        qtbot.addWidget(self.window)
        self.document = PlanDocument(self.window)
        self.dialogs = ScriptedDialogs()
        self.messages: list[str] = []
        self.canvas_shown = 0
        autosaver = Autosaver(self.document, recovery_dir, 60_000, self.window)
        self.files = PlanFiles(
            self.document, autosaver, self.dialogs, settings, self._message, self._canvas,
            self.window,
        )  # fmt: skip

    def _message(self, text: str, timeout_ms: int = 8000) -> None:
        self.messages.append(text)

    def _canvas(self) -> None:
        self.canvas_shown += 1


@pytest.fixture
def harness(qtbot: Any, app_settings: AppSettings, recovery_dir: Path) -> Harness:
    return Harness(qtbot, app_settings, recovery_dir)


def test_open_names_a_corrupt_file_and_then_opens_a_good_one(
    harness: Harness, figure3_path: Path, tmp_path: Path, app_settings: AppSettings
) -> None:
    corrupt = tmp_path / "broken.costar.json"
    corrupt.write_text('{"format": "costar-plan", "tree": [1', encoding="utf-8")
    assert harness.files.open_plan(corrupt) is False
    assert [title for title, _ in harness.dialogs.errors] == ["Cannot open the plan"]
    assert "broken.costar.json" in harness.dialogs.errors[0][1]
    assert harness.files.open_plan(figure3_path) is True
    assert harness.document.path == figure3_path
    assert harness.messages == [f"Opened {figure3_path}"]
    assert str(figure3_path.resolve()) in app_settings.recent_files()
    harness.files.update_title()
    assert harness.window.windowTitle().startswith(f"{figure3_path.name} — ")


def test_saving_a_shipped_example_asks_for_a_new_file_and_adds_the_suffix(
    harness: Harness, figure3_path: Path, tmp_path: Path
) -> None:
    assert harness.files.open_plan(figure3_path)
    shipped = figure3_path.read_bytes()
    harness.dialogs.save_paths = [str(tmp_path / "mine")]
    assert harness.files.save_plan() is True
    saved = tmp_path / "mine.costar.json"
    assert saved.is_file() and harness.document.path == saved
    assert harness.messages[-1] == f"Saved {saved}"
    assert figure3_path.read_bytes() == shipped  # the example stays as shipped


def test_new_plan_asks_about_unsaved_changes_and_cancel_keeps_them(
    harness: Harness, figure3_path: Path
) -> None:
    assert harness.files.open_plan(figure3_path)
    harness.document.rename(harness.document.plan.tree.id, "renamed")  # type: ignore[union-attr]
    harness.dialogs.save_answers = ["cancel"]
    harness.files.new_plan()
    assert harness.dialogs.asked == [("save", figure3_path.name)]
    assert harness.document.dirty and harness.document.path == figure3_path
    assert harness.canvas_shown == 0
    harness.files.new_plan()  # the scripted answer is now "discard"
    assert harness.document.path is None and not harness.document.dirty
    assert harness.canvas_shown == 1
