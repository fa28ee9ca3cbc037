"""CellControl: the cell chooser and Reset Cell, following the session and the run.

The window places the chooser and the action in its toolbar and menus; what they do lives
here: switching the cell in use (in the background, see CellSession), resetting it, and
enabling both only while no plan runs and no cell opens.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QComboBox, QLabel, QWidget

from engine.executor import ExecutorState
from instructor_app.dialogs import Dialogs
from instructor_app.document.editing import PlanDocument
from instructor_app.runtime.controller import RunController
from instructor_app.runtime.run_view import RunActions
from instructor_app.runtime.session import CellSession
from instructor_app.views import Views

OPEN_CELL_FILE = "Open cell file…"


class ShowMessage(Protocol):
    """A status-bar message (``timeout_ms`` 0: until the next one)."""

    def __call__(self, text: str, timeout_ms: int = ...) -> None: ...


class CellControl(QObject):
    """Owns the cell chooser (``combo``, with ``label``) and the Reset Cell action.

    Args:
        session: the cell in use; its signals move the chooser.
        controller: the run (no switching or resetting while it runs).
        document: the plan, whose scene a reset restores.
        views: the panels (the registry goes to them, failures to the log).
        run_actions: Run, Step, ...: disabled too while a cell opens.
        dialogs: asks for a cell file, shows a failed opening.
        show_message: the window's status-bar message.
        window: the parent of the widgets and dialogs.
    """

    def __init__(
        self,
        session: CellSession,
        controller: RunController,
        document: PlanDocument,
        views: Views,
        run_actions: RunActions,
        dialogs: Dialogs,
        show_message: ShowMessage,
        window: QWidget,
    ) -> None:
        super().__init__(window)
        self.session, self.controller, self.document = session, controller, document
        self.views, self.run_actions, self.dialogs = views, run_actions, dialogs
        self.show_message, self.window = show_message, window
        self.label = QLabel(" Cell: ")
        self.combo = QComboBox(window)
        self.combo.setObjectName("CellCombo")
        self.combo.setToolTip(
            "The cell plans run on: the simulated cell, none (no robot), or a cell file"
        )
        for name in session.cell_names():
            self.combo.addItem(name, name)
        self.combo.addItem(OPEN_CELL_FILE, "")  # data "": ask for a file
        self._show_cell(session.name)
        self.reset_action = QAction("Reset &Cell", window)
        self.reset_action.setObjectName("reset_cell")
        self.reset_action.setShortcut(QKeySequence("Ctrl+R"))
        self.reset_action.triggered.connect(self.reset_cell)
        self.reset_action.setToolTip(
            "Put the robot and the objects back where the scene starts them"
        )

    def wire(self) -> None:
        """Follow the session's cell signals and let the chooser switch the cell."""
        self.session.registry_changed.connect(self._on_registry)
        self.session.cell_changed.connect(self._on_cell_changed)
        self.session.cell_failed.connect(self._on_cell_failed)
        self.session.cell_opening.connect(self._on_cell_opening)
        self.session.cell_ready.connect(lambda _ok: self.follow_run_state(self.controller.state))
        self.combo.activated.connect(
            lambda index: self.switch_cell(str(self.combo.itemData(index) or ""))
        )

    def follow_run_state(self, state: object) -> None:
        """The cell chooser, Reset and Run follow the run's state; all wait while a cell opens."""
        idle = state in (ExecutorState.READY, ExecutorState.FINISHED)
        opening = bool(self.session.opening)
        self.combo.setEnabled(idle and not opening)
        self.reset_action.setEnabled(idle and not opening)
        self.run_actions.update_state(state)
        if opening:
            self.run_actions.run.setEnabled(False)
            self.run_actions.step.setEnabled(False)

    def reset_cell(self) -> None:
        """Put robot and objects back to the scene's start (not while a plan runs)."""
        if self.controller.reset_cell(self.document.plan.scene):
            self.views.canvas.clear_statuses()
            self.show_message(f"The {self.session.name} cell was reset")
        elif self.session.opening:
            self.show_message(f"Wait until the {self.session.opening} cell is open.")
        else:
            self.show_message("Stop the run before resetting the cell.")

    def use_plan_scene(self) -> None:
        """The simulated cell holds the scene the plan names (the default when it names
        none): it reopens with it now, or, while a plan runs, on the next reset.
        """
        if self.controller.is_running:
            self.session.scene = self.document.plan.scene or self.session.default_scene
        elif self.session.use_scene(self.document.plan.scene):
            self.show_message(f"Loading the scene {self.session.scene}…", 0)

    def _show_cell(self, name: str) -> None:
        """Select ``name`` in the cell chooser (a cell file gets an entry of its own)."""
        index = self.combo.findData(name)
        if index < 0:
            index = self.combo.count() - 1  # before "Open cell file…"
            self.combo.insertItem(index, Path(name).name, name)
            self.combo.setItemData(index, name, Qt.ItemDataRole.ToolTipRole)
        self.combo.setCurrentIndex(index)

    def switch_cell(self, name: str) -> None:
        """Open another cell: a name, a cell file, or "" to ask for one (not while running,
        not while another opens). It opens in the background (see CellSession): the window
        answers meanwhile, and the cell that was open stays in use until the new one is.
        """
        if self.session.opening:
            self._show_cell(self.session.opening)
            self.show_message(
                f"The {self.session.opening} cell is still opening; choose again when it is."
            )
            return
        if not name:
            folder = str(Path(self.session.name).parent) if Path(self.session.name).suffix else ""
            name = self.dialogs.open_cell_path(self.window, folder)
            if not name:
                self._show_cell(self.session.name)
                return
        if name == self.session.name:
            return
        if self.controller.is_running:
            self._show_cell(self.session.name)
            self.show_message("Stop the run before switching the cell.")
            return
        self.session.open_in_background(name)

    def _on_registry(self, registry: Any) -> None:
        self.views.set_registry(registry)

    def _on_cell_changed(self, name: str) -> None:
        self._show_cell(name)
        self.show_message(f"Cell in use: {name}")

    def _on_cell_opening(self, name: str, words: str) -> None:
        """(A background opening started) Say what it does until it ends; no run meanwhile."""
        self._show_cell(name)
        self.show_message(words, 0)
        self.follow_run_state(self.controller.state)

    def _on_cell_failed(self, message: str) -> None:
        self._show_cell(self.session.name)
        still = f"still using the {self.session.name} cell" if self.session.cell else "no cell"
        text = f"{message.rstrip('.')}; {still}"
        self.show_message(text, 0)
        self.views.log.append(text, "error")
        self.dialogs.error(self.window, "Cell", message)
