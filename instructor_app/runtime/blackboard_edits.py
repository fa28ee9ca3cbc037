"""Changing a named parameter of a paused run, undoably.

A value typed in the Blackboard panel is set on the run (:meth:`RunController.set_entry`: the
engine writes it between ticks) as one :class:`SetEntryCommand` on the run's own undo stack,
not the document's: the plan does not change (saving is not asked for) and the edit means
nothing once the run goes on. While the run is paused and has such edits, the Edit menu's
Undo and Redo (Ctrl+Z, Ctrl+Y) act on them; otherwise on the plan. The stack is emptied
when the run goes on or ends.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QObject
from PySide6.QtGui import QUndoCommand, QUndoGroup, QUndoStack

from engine.blackboard import BlackboardEntry, BlackboardError
from engine.executor import ExecutorState
from engine.spec import PlanSpec
from engine.units import format_value
from instructor_app.panels.blackboard import BlackboardPanel
from instructor_app.runtime.controller import RunController

__all__ = ["BlackboardEdits", "SetEntryCommand"]


class SetEntryCommand(QUndoCommand):
    """Set ``key`` of the paused run to ``new`` (undo: back to ``old``).

    Pushed after the first set succeeded (``done``), so that a refused value never reaches
    the stack.
    """

    def __init__(self, controller: RunController, key: str, old: Any, new: Any) -> None:
        super().__init__(f"Set {key} to {format_value(new)}")
        self.controller, self.key, self.old, self.new = controller, key, old, new
        self._done = True

    def redo(self) -> None:
        if self._done:
            self._done = False
            return
        self.controller.set_entry(self.key, self.new)

    def undo(self) -> None:
        self.controller.set_entry(self.key, self.old)


class BlackboardEdits(QObject):
    """Shows the run's named parameters in the panel and turns its edits into commands.

    Args:
        controller: the run.
        panel: the Blackboard panel.
        group: the window's undo group (its Undo and Redo actions are the Edit menu's).
        plan_stack: the document's undo stack, active whenever the run has no edits.
    """

    def __init__(
        self,
        controller: RunController,
        panel: BlackboardPanel,
        group: QUndoGroup,
        plan_stack: QUndoStack,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self.controller, self.panel = controller, panel
        self.group, self.plan_stack = group, plan_stack
        self.stack = QUndoStack(self)
        group.addStack(self.stack)
        panel.set_writer_names(controller.label)
        controller.entries_written.connect(self._show)
        controller.run_state_changed.connect(self._on_state)
        panel.value_edited.connect(self.set_value)
        self.stack.indexChanged.connect(lambda _index: self._choose_stack())

    def set_value(self, key: str, value: Any) -> bool:
        """Set ``key`` of the paused run (undoably); False, said in the panel, if refused."""
        old = self.panel.values().get(key)
        try:
            self.controller.set_entry(key, value)
        except (BlackboardError, RuntimeError) as exc:
            self.panel.show_message(f"Not changed: {exc}", error=True)
            return False
        self.stack.push(SetEntryCommand(self.controller, key, old, value))
        return True

    def _show(self, entries: list[BlackboardEntry]) -> None:
        self.panel.set_entries(entries)

    def _on_state(self, state: object) -> None:
        if state is not ExecutorState.PAUSED:
            self.stack.clear()
        if state in (ExecutorState.RUNNING, ExecutorState.PAUSED):
            plan = self.controller.document.plan
            self.panel.set_shared_names(_shared_names(plan))
        self.panel.set_editable(state is ExecutorState.PAUSED)
        self._choose_stack()

    def _choose_stack(self) -> None:
        paused = self.controller.state is ExecutorState.PAUSED
        active = self.stack if paused and self.stack.count() else self.plan_stack
        if self.group.activeStack() is not active:
            self.group.setActiveStack(active)


def _shared_names(plan: PlanSpec) -> set[str]:
    return {name for subtree in plan.subtrees for name in subtree.shared_names}
