"""The run's controls and small views: Run/Pause/Step/Stop actions, the running-nodes list
and the failure button of the status bar. They show the RunController; none runs anything.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Qt, Signal
from PySide6.QtGui import QAction, QIcon, QKeySequence
from PySide6.QtWidgets import QListWidget, QListWidgetItem, QPushButton, QStyle, QWidget

from engine.executor import ExecutorState
from instructor_app.runtime.controller import (
    RunController,
    RunOutcome,
)

__all__ = ["FailureButton", "RunActions", "RunningNodesPanel", "RunPresenter"]

LabelFn = Callable[[str], str]


class RunActions(QObject):
    """Run (F5), Pause, Step (F10) and Stop (Shift+F5), enabled by the run's state.

    Args:
        controller: the run they control.
        parent: owner of the actions (the main window, so that shortcuts work everywhere).
    """

    def __init__(self, controller: RunController, parent: QWidget) -> None:
        super().__init__(parent)
        self.controller = controller
        self.run = self._action(parent, "&Run", "F5", QStyle.StandardPixmap.SP_MediaPlay)
        self.pause = self._action(parent, "&Pause", "", QStyle.StandardPixmap.SP_MediaPause)
        self.step = self._action(parent, "S&tep", "F10", QStyle.StandardPixmap.SP_MediaSkipForward)
        self.stop = self._action(parent, "&Stop", "Shift+F5", QStyle.StandardPixmap.SP_MediaStop)
        self.run.setToolTip("Run the plan on the cell (F5); continues a paused run")
        self.pause.setToolTip("Pause the run after the current tick")
        self.step.setToolTip("One tick, then pause (F10)")
        self.stop.setToolTip("Stop the run: what runs is halted and the arm stops (Shift+F5)")
        self.run.triggered.connect(controller.run)
        self.pause.triggered.connect(controller.pause)
        self.step.triggered.connect(controller.step)
        self.stop.triggered.connect(controller.stop)
        controller.run_state_changed.connect(self.update_state)
        self.update_state(controller.state)

    @staticmethod
    def _action(parent: QWidget, text: str, shortcut: str, icon: QStyle.StandardPixmap) -> QAction:
        action = QAction(QIcon(parent.style().standardIcon(icon)), text, parent)
        if shortcut:
            action.setShortcut(QKeySequence(shortcut))
            action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        return action

    def all(self) -> list[QAction]:
        return [self.run, self.pause, self.step, self.stop]

    def update_state(self, state: object) -> None:
        idle = state in (ExecutorState.READY, ExecutorState.FINISHED)
        self.run.setEnabled(idle or state == ExecutorState.PAUSED)
        self.pause.setEnabled(state == ExecutorState.RUNNING)
        self.step.setEnabled(idle or state == ExecutorState.PAUSED)
        self.stop.setEnabled(state in (ExecutorState.RUNNING, ExecutorState.PAUSED))


class RunningNodesPanel(QListWidget):
    """The nodes now RUNNING, outermost first; clicking one selects it on the canvas.

    Args:
        label: node id -> what to show (the node's path in the plan).

    Signals:
        node_selected(str): the user picked a node.
    """

    node_selected = Signal(str)

    def __init__(self, label: LabelFn, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._label = label
        self._held = ""
        self.setObjectName("RunningNodesPanel")
        self.itemActivated.connect(self._picked)
        self.itemClicked.connect(self._picked)

    def set_nodes(self, node_ids: list[str]) -> None:
        self.setUpdatesEnabled(False)  # one repaint for the whole list (a timeline's drag)
        try:
            self.clear()
            for node_id in node_ids:
                item = QListWidgetItem(self._label(node_id))
                item.setData(Qt.ItemDataRole.UserRole, node_id)
                self.addItem(item)
            if self._held:
                self._mark_held()
        finally:
            self.setUpdatesEnabled(True)

    def set_held(self, reason: str, text: str = "") -> None:
        """The run is held (why; "" when it goes on): the running nodes say so."""
        self._held = text or (f"held: {reason}" if reason else "")
        self._mark_held()

    def _mark_held(self) -> None:
        held = self._held
        for i in range(self.count()):
            item = self.item(i)
            label = self._label(item.data(Qt.ItemDataRole.UserRole))
            item.setText(f"{label} ({held})" if held else label)
            item.setToolTip(held)

    def node_ids(self) -> list[str]:
        return [self.item(i).data(Qt.ItemDataRole.UserRole) for i in range(self.count())]

    def _picked(self, item: QListWidgetItem) -> None:
        self.node_selected.emit(item.data(Qt.ItemDataRole.UserRole))


class FailureButton(QPushButton):
    """The status bar's "grasp CUP failed 4 times (grasp_failed): nothing between the
    fingers"; the tooltip says all of it (the nodes that passed it up); clicking selects the
    node.

    Signals:
        node_selected(str): the failing node, when clicked.
    """

    node_selected = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.node_id = ""
        self.setFlat(True)
        self.setObjectName("FailureButton")
        self.setStyleSheet("QPushButton { color: #b3261e; text-align: left; }")
        self.setIcon(self.style().standardIcon(QStyle.StandardPixmap.SP_MessageBoxCritical))
        self.clicked.connect(lambda: self.node_selected.emit(self.node_id))
        self.show_failure("", "")

    def show_failure(self, node_id: str, text: str) -> None:
        """Show ``text``, what failed and why (its first part, up to "; ", on the button)."""
        self.node_id = node_id
        if not node_id:
            self.setText("")
            self.setToolTip("")
            self.hide()
            return
        self.setText(text.split("; ")[0])
        self.setToolTip(f"{text}\nClick to select the node.")
        self.show()


class RunPresenter(QObject):
    """Shows a run on the canvas and panels: clears them when a run starts, reports a refused
    plan in the log, and says how the run ended in the status bar.

    Args:
        controller: the run.
        canvas: has ``clear_statuses()``.
        blackboard: has ``clear()``.
        log: has ``append(text, level)``.
        show_message: puts a line in the status bar.

    Signals:
        problems_shown: a plan was refused; the problems list should come to the front.
    """

    problems_shown = Signal()

    def __init__(
        self,
        controller: RunController,
        canvas: Any,
        blackboard: Any,
        log: Any,
        show_message: Callable[[str], None],
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._canvas, self._blackboard, self._log = canvas, blackboard, log
        self._show = show_message
        self._active = False
        controller.run_state_changed.connect(self._on_state)
        controller.run_refused.connect(self._on_refused)
        controller.run_finished.connect(self._on_finished)
        controller.hold_changed.connect(self._on_hold)

    def _on_hold(self, reason: str, text: str) -> None:
        if reason:
            self._show(f"Running, {text}")
        elif self._active:
            self._show("Running…")

    def _on_state(self, state: object) -> None:
        if state in (ExecutorState.RUNNING, ExecutorState.PAUSED) and not self._active:
            self._active = True  # a new run: last run's colours and values go
            self._canvas.clear_statuses()
            self._blackboard.clear()
        elif state in (ExecutorState.READY, ExecutorState.FINISHED):
            self._active = False
        if state is ExecutorState.RUNNING:
            self._show("Running…")
        elif state is ExecutorState.PAUSED:
            self._show("Paused")

    def _on_refused(self, problems: list[Any]) -> None:
        for problem in problems:
            self._log.append(str(problem), "error")
        count = len(problems)
        self._show(
            f"The plan was not started: {count} problem{'s' * (count != 1)} to fix (see Problems)"
        )
        self.problems_shown.emit()

    def _on_finished(self, outcome: object) -> None:
        assert isinstance(outcome, RunOutcome)
        event = outcome.event
        if event.reason != "finished":
            self._show(f"Run {event.reason} after {event.tick} ticks")
        elif outcome.cause is not None:  # why: the root cause, with its count
            self._show(f"Run ended: FAILURE after {event.tick} ticks: {outcome.cause.describe()}")
        else:
            self._show(f"Run ended: {event.status.value} after {event.tick} ticks")
