"""CellControl on its own: a session, a run controller, views and scripted dialogs."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtWidgets import QWidget

from engine.executor import ExecutorState
from instructor_app.cell_control import OPEN_CELL_FILE, CellControl
from instructor_app.document.editing import PlanDocument
from instructor_app.runtime.controller import RunController
from instructor_app.runtime.run_view import RunActions
from instructor_app.runtime.session import CellSession
from instructor_app.views import make_views
from tests.instructor_app.gui_driver import ScriptedDialogs


class Harness:
    def __init__(self, qtbot: Any, session: CellSession, folder: Path) -> None:
        self.window = QWidget()
        qtbot.addWidget(self.window)
        self.session = session
        document = PlanDocument(self.window)
        self.controller = controller = RunController(document, session, parent=self.window)
        self.views = make_views(document, session, self.window, folder)
        self.run_actions = RunActions(controller, self.window)
        self.dialogs = ScriptedDialogs()
        self.messages: list[tuple[str, int]] = []
        self.cells = CellControl(
            session, controller, document, self.views, self.run_actions, self.dialogs,
            self._message, self.window,
        )  # fmt: skip
        self.cells.wire()

    def _message(self, text: str, timeout_ms: int = 8000) -> None:
        self.messages.append((text, timeout_ms))


@pytest.fixture
def harness(qtbot: Any, none_session: CellSession, tmp_path: Path) -> Iterator[Harness]:
    made = Harness(qtbot, none_session, tmp_path)
    yield made
    made.controller.shutdown()  # as MainWindow.shutdown does
    made.views.teacher.shutdown()
    made.views.objects.shutdown()


def test_the_chooser_lists_the_cells_and_shows_the_one_in_use(harness: Harness) -> None:
    combo = harness.cells.combo
    names = [combo.itemText(i) for i in range(combo.count())]
    assert names[-1] == OPEN_CELL_FILE and "none" in names
    assert combo.currentData() == "none"


def test_a_cancelled_cell_file_choice_keeps_the_cell_in_use(harness: Harness) -> None:
    combo = harness.cells.combo
    combo.setCurrentIndex(combo.count() - 1)  # "Open cell file…", as a click would
    harness.cells.switch_cell("")  # the dialog answers "" (cancelled)
    assert combo.currentData() == "none" and not harness.session.opening
    harness.cells.switch_cell("none")  # the cell in use: nothing to do
    assert not harness.session.opening and not harness.messages


def test_a_failed_opening_is_said_logged_and_shown(harness: Harness) -> None:
    harness.session.cell_failed.emit("The cell file x.json is not a cell.")
    text = "The cell file x.json is not a cell; still using the none cell"
    assert harness.messages == [(text, 0)]
    assert harness.views.log.lines()[-1].endswith(text)
    assert harness.dialogs.errors == [("Cell", "The cell file x.json is not a cell.")]


def test_the_chooser_and_reset_wait_while_a_plan_runs(harness: Harness) -> None:
    harness.cells.follow_run_state(ExecutorState.RUNNING)
    assert not harness.cells.combo.isEnabled() and not harness.cells.reset_action.isEnabled()
    harness.cells.follow_run_state(ExecutorState.FINISHED)
    assert harness.cells.combo.isEnabled() and harness.cells.reset_action.isEnabled()
