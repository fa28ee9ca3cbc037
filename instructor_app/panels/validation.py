"""The list of a plan's problems, refreshed shortly after each edit.

Validation runs in the GUI thread but not on every signal: a single-shot timer restarts on
each ``plan_changed`` and validates once the edits pause (~150 ms), so a paste of a hundred
nodes validates once.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QStyle, QTreeWidget, QTreeWidgetItem, QVBoxLayout, QWidget

from engine.operations import OperationSource
from engine.validation import EMPTY_PLAN, ERROR, Problem, SubtreeSource, validate_plan
from instructor_app.document import PlanDocument

__all__ = ["ValidationPanel", "DEBOUNCE_MS"]

DEBOUNCE_MS = 150
_PROBLEM_ROLE = Qt.ItemDataRole.UserRole + 1


class ValidationPanel(QWidget):
    """Problems of the document's plan on the current cell.

    Signals:
        node_selected(str): the user picked a problem that concerns this node.
        summary_changed(int, int): the numbers of errors and warnings after a validation (an
            empty plan counts none).
        problems_changed(list): every problem after a validation (the inspector marks fields).
    """

    node_selected = Signal(str)
    summary_changed = Signal(int, int)
    problems_changed = Signal(list)

    def __init__(
        self, document: PlanDocument, registry: OperationSource, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.document = document
        self._registry = registry
        self._problems: list[Problem] = []
        self.list = QTreeWidget()
        self.list.setColumnCount(3)
        self.list.setHeaderLabels(["", "Where", "Problem"])
        self.list.setRootIsDecorated(False)
        self.list.setUniformRowHeights(True)
        self.list.setWordWrap(True)
        self.list.itemSelectionChanged.connect(self._selection_changed)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.list)
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(DEBOUNCE_MS)
        self._timer.timeout.connect(self.revalidate)
        document.plan_changed.connect(self._timer.start)
        self.revalidate()

    _library: SubtreeSource | None = None

    def set_library(self, library: SubtreeSource | None) -> None:
        """The subtree library: instances of subtrees it has newer versions of are shown."""
        self._library = library
        self.revalidate()

    def set_registry(self, registry: OperationSource) -> None:
        """Validate against another cell's operations (at once)."""
        self._registry = registry
        self.revalidate()

    def problems(self) -> list[Problem]:
        """The problems found by the last validation."""
        return list(self._problems)

    def pending(self) -> bool:
        """Whether a validation is scheduled (edits since the last one)."""
        return self._timer.isActive()

    def revalidate(self) -> None:
        """Validate now (the timer calls this after edits pause)."""
        self._timer.stop()
        problems = validate_plan(self.document.plan, self._registry, self._library)
        # An empty plan (a new one) is where the user starts, not a mistake: the summary
        # gives a hint instead (a run still refuses it and says why).
        self._problems = [p for p in problems if p.message != EMPTY_PLAN]
        self._show()
        errors = sum(1 for p in self._problems if p.severity == ERROR)
        self.summary_changed.emit(errors, len(self._problems) - errors)
        self.problems_changed.emit(list(self._problems))

    def _show(self) -> None:
        style = self.style()
        icons = {
            ERROR: style.standardIcon(QStyle.StandardPixmap.SP_MessageBoxCritical),
            "warning": style.standardIcon(QStyle.StandardPixmap.SP_MessageBoxWarning),
        }
        self.list.blockSignals(True)
        self.list.clear()
        for problem in self._problems:
            where = problem.path + (f" [{problem.field}]" if problem.field else "")
            row = QTreeWidgetItem(self.list, ["", where, problem.message])
            row.setIcon(0, icons.get(problem.severity, icons["warning"]))
            row.setToolTip(0, problem.severity)
            row.setToolTip(2, problem.message)
            row.setData(0, _PROBLEM_ROLE, problem)
        self.list.blockSignals(False)
        self.list.resizeColumnToContents(0)

    def _selection_changed(self) -> None:
        rows = self.list.selectedItems()
        if not rows:
            return
        problem = rows[0].data(0, _PROBLEM_ROLE)
        if isinstance(problem, Problem) and problem.node_id:
            self.node_selected.emit(problem.node_id)
