"""The Debug menu and the node's debug commands: breakpoints (F9), stepping, skip and force.

They show and change the RunController's :class:`~instructor_app.runtime.debugging.RunDebugging`
and step its run; the canvas draws the marks (a red dot for a breakpoint, "skipped",
"forced: grasp_failed", an orange border on the node the run is paused at) and the status
bar says where and why the run paused.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMenu, QWidget

from engine.debugger import Breakpoint, Forced
from engine.error_types import ErrorType
from engine.executor import ExecutorState
from engine.script import ScriptSyntaxError
from engine.status import FAILURE, SUCCESS
from instructor_app.canvas.actions import MenuEntry
from instructor_app.canvas.view import CanvasView
from instructor_app.runtime.controller import RunController
from instructor_app.settings import AppSettings

__all__ = ["DebugActions"]

# The error types a forced failure offers, the common ones first.
FAIL_TYPES = (
    ErrorType.GRASP_FAILED,
    ErrorType.NOT_FOUND,
    ErrorType.OBJECT_LOST,
    ErrorType.COLLISION,
    ErrorType.TIMEOUT,
    ErrorType.PROTECTIVE_STOP,
    ErrorType.FAILED,
)


AskText = Callable[[str, str, str], "str | None"]


def _where(breakpoint: Breakpoint) -> str:
    """Where the breakpoint pauses: "before", "after" or "before and after"."""
    if breakpoint.before and breakpoint.after:
        return "before and after"
    return "before" if breakpoint.before else "after"


class DebugActions(QObject):
    """Toggle Breakpoint (F9), Step (F11), Step Over (Shift+F11), Run to Selected Node
    (Ctrl+F10) and Continue (F8); marks on the canvas; what the status bar says.

    Args:
        controller: the run.
        canvas: where the nodes are selected and marked.
        say: shows a line in the status bar (text, for how many ms; 0: until replaced).
        parent: owner of the actions (the main window, so that shortcuts work everywhere).
        settings: where the breakpoints of each plan are kept (None: nowhere).
        ask_text: asks the operator for a line of text (title, label, text now; None:
            cancelled), for a breakpoint's condition.
    """

    def __init__(
        self,
        controller: RunController,
        canvas: CanvasView,
        say: Callable[[str, int], None],
        parent: QWidget,
        settings: AppSettings | None = None,
        ask_text: AskText | None = None,
    ) -> None:
        super().__init__(parent)
        self.controller, self.canvas, self._say = controller, canvas, say
        self._settings = settings
        self._ask_text: AskText = ask_text or (lambda _title, _label, _text: None)
        self.debugging = controller.debugging
        self.paused_at = ""  # the plan node the run is paused at ("" when it is not)
        self.toggle = self._action(parent, "Toggle &Breakpoint", "F9", self.toggle_selected)
        self.step = self._action(parent, "&Step", "F11", controller.step_next)
        self.step_over = self._action(parent, "Step &Over", "Shift+F11", controller.step_over)
        self.run_to = self._action(parent, "Run to Selected &Node", "Ctrl+F10", self._run_to)
        self.resume = self._action(parent, "&Continue", "F8", controller.resume)
        self.toggle.setToolTip("Pause the run before the selected node (F9)")
        self.step.setToolTip("Run to the next change of a node's status, then pause (F11)")
        self.step_over.setToolTip("Run the node paused at to its end, then pause (Shift+F11)")
        self.run_to.setToolTip("Run until the selected node is about to start (Ctrl+F10)")
        self.resume.setToolTip("Go on to the next breakpoint or the end (F8)")
        self.debugging.changed.connect(self.refresh)
        controller.run_paused.connect(self._on_paused)
        controller.run_state_changed.connect(self._on_state)
        canvas.document.plan_changed.connect(self._on_plan_changed)
        canvas.document.plan_reset.connect(self._on_plan_reset)
        self._on_state(controller.state)

    @staticmethod
    def _action(parent: QWidget, text: str, shortcut: str, slot: Callable[[], object]) -> QAction:
        action = QAction(text, parent)
        action.setShortcut(QKeySequence(shortcut))
        action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        action.triggered.connect(lambda _checked=False: slot())
        return action

    def fill_menu(self, menu: QMenu) -> None:
        menu.addAction(self.toggle)
        menu.addSeparator()
        menu.addActions([self.step, self.step_over, self.run_to, self.resume])

    # ------------------------------------------------------------------ commands

    def _selected(self) -> str:
        ids = self.canvas.selected_ids()
        return ids[0] if len(ids) == 1 else ""

    def toggle_selected(self) -> None:
        node_id = self._selected()
        if not node_id:
            self._say("Select one node to set a breakpoint on", 8000)
            return
        on = self._toggle(node_id)
        label = self.canvas.document.node(node_id).label
        self._say(f"Breakpoint before {label} {'set' if on else 'cleared'}", 8000)

    def _run_to(self) -> None:
        node_id = self._selected()
        if not node_id:
            self._say("Select the node to run to", 8000)
            return
        self.controller.run_to(node_id)

    def node_entries(self, node_id: str) -> list[MenuEntry]:
        """The debug entries of a node's context menu."""
        debugging = self.debugging
        skipped = debugging.is_skipped(node_id)
        entries: list[MenuEntry] = [
            (
                "Clear Breakpoint" if debugging.has_breakpoint(node_id) else "Set Breakpoint",
                functools.partial(self._toggle, node_id),
            ),
            ("Breakpoint", self._breakpoint_entries(node_id)),
            (
                "Do Not Skip This Node" if skipped else "Skip This Node",
                functools.partial(debugging.set_skipped, node_id, not skipped),
            ),
        ]
        force: list[tuple[str, Callable[[], object]]] = [
            ("Succeed", functools.partial(debugging.set_forced, node_id, Forced(SUCCESS)))
        ]
        for error in FAIL_TYPES:
            forced = Forced(FAILURE, error)
            force.append((f"Fail: {error.value}", functools.partial(self._force, node_id, forced)))
        if debugging.forced(node_id) is not None:
            force.append(("Run It as Usual", functools.partial(self._force, node_id, None)))
        entries.append(("Force Result", force))
        return entries

    def _breakpoint_entries(self, node_id: str) -> list[tuple[str, Callable[[], object]]]:
        """Where the run pauses at the node: before it, after it, both; on a condition."""
        now = self.debugging.breakpoint(node_id)
        condition = now.condition if now is not None else ""
        where = [("Before", True, False), ("After", False, True), ("Before and After", True, True)]
        entries: list[tuple[str, Callable[[], object]]] = [
            (text, functools.partial(self._put, Breakpoint(node_id, before, after, condition)))
            for text, before, after in where
        ]
        entries.append(("Only When…", functools.partial(self._ask_condition, node_id)))
        if now is not None:
            entries.append(("Clear", functools.partial(self._put_none, node_id)))
        return entries

    def _ask_condition(self, node_id: str) -> None:
        """Ask for the condition (a script on the node's names; empty: always)."""
        now = self.debugging.breakpoint(node_id) or Breakpoint(node_id)
        label = self.canvas.document.node(node_id).label
        text = self._ask_text(
            "Breakpoint condition",
            f"Pause at {label} only when this is true (a script, e.g. COUNT >= 3; empty: always):",
            now.condition,
        )
        if text is None:
            return
        try:
            self._put(Breakpoint(node_id, now.before, now.after, text.strip()))
        except ScriptSyntaxError as exc:
            self._say(f"Breakpoint condition not set: {exc}", 0)

    def _put(self, breakpoint: Breakpoint) -> None:
        self.debugging.set_breakpoint(breakpoint.node_id, breakpoint)
        self._keep()
        label = self.canvas.document.node(breakpoint.node_id).label
        when = f" when {breakpoint.condition}" if breakpoint.condition else ""
        self._say(f"Breakpoint {_where(breakpoint)} {label}{when} set", 8000)

    def _put_none(self, node_id: str) -> None:
        self.debugging.set_breakpoint(node_id, None)
        self._keep()

    def _toggle(self, node_id: str) -> bool:
        on = self.debugging.toggle_breakpoint(node_id)
        self._keep()
        return on

    def _keep(self) -> None:
        """Keep the plan's breakpoints in the settings (never in the plan file)."""
        if self._settings is not None:
            plan_id = self.canvas.document.plan.id
            self._settings.set_breakpoints(plan_id, self.debugging.all_breakpoints())

    def _force(self, node_id: str, forced: Forced | None) -> None:
        self.debugging.set_forced(node_id, forced)

    # ------------------------------------------------------------------ marks

    def refresh(self) -> None:
        """Redraw the marks of every node."""
        plan = self.canvas.document.plan
        notes = {node.id: self.debugging.note(node.id) for _, node in plan.walk()}
        notes = {k: v for k, v in notes.items() if v}
        self.canvas.set_debug_marks(self.debugging.breakpoints, notes, self.paused_at)

    def _on_plan_reset(self) -> None:
        """Another plan (or the same, reloaded): its breakpoints as they were kept."""
        plan = self.canvas.document.plan
        kept = self._settings.breakpoints(plan.id) if self._settings is not None else []
        ids = {node.id for _, node in plan.walk()}
        self.debugging.load([b for b in kept if b.node_id in ids])

    def _on_plan_changed(self) -> None:
        self.debugging.forget({node.id for _, node in self.canvas.document.plan.walk()})
        self.refresh()  # a rebuilt canvas has lost its marks

    def _on_paused(self, node_id: str, why: str) -> None:
        self.paused_at = node_id
        self.refresh()
        node = self.canvas.document.plan.find(node_id)
        self._say(f"Paused at {node.label if node else node_id}: {why}", 0)
        if node_id:
            self.canvas.ensure_visible(node_id)

    def _on_state(self, state: object) -> None:
        paused = state == ExecutorState.PAUSED
        running = state in (ExecutorState.RUNNING, ExecutorState.PAUSED)
        for action in (self.step, self.step_over, self.run_to):
            action.setEnabled(paused or not running)
        self.resume.setEnabled(paused)
        if not paused and self.paused_at:
            self.paused_at = ""
            self.refresh()
            self._say("", 1)  # the pause's line goes with the pause
