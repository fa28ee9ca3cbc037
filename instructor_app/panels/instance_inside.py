"""The inside of the selected subtree instance, with the statuses of a run as they change.

On the canvas an instance is one node; this panel opens it: its subtree's nodes as a tree
(nested instances opened too), each with the status the run gave it, coloured like the
canvas (runtime ids ``<instance id>/<inner id>``, see :mod:`engine.instances`).
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QBrush, QColor
from PySide6.QtWidgets import QLabel, QTreeWidget, QTreeWidgetItem, QVBoxLayout, QWidget

from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from instructor_app.canvas.style import STATUS_COLOURS

__all__ = ["InstanceInsidePanel"]


class InstanceInsidePanel(QWidget):
    """The selected instance's inside and its live statuses."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.title = QLabel("Select a subtree instance to see its inside.", self)
        self.tree = QTreeWidget(self)
        self.tree.setHeaderLabels(["Node", "Status"])
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.title)
        layout.addWidget(self.tree)
        self._rows: dict[str, QTreeWidgetItem] = {}
        self._statuses: dict[str, Status] = {}

    def show_instance(self, plan: PlanSpec, instance: NodeSpec | None) -> None:
        """Open ``instance`` (None: nothing) of ``plan``; statuses seen so far stay shown."""
        self.tree.clear()
        self._rows = {}
        subtree = plan.subtree(instance.subtree) if instance and instance.subtree else None
        if instance is None or subtree is None:
            self.title.setText("Select a subtree instance to see its inside.")
            return
        self.title.setText(f"Inside {instance.label} ({subtree.name}, version {subtree.version})")
        self._add(plan, subtree.tree, f"{instance.id}/", None, (subtree.ref,))
        self.tree.expandAll()
        self.tree.resizeColumnToContents(0)
        for runtime_id, status in self._statuses.items():
            self._colour(runtime_id, status)

    def _add(
        self,
        plan: PlanSpec,
        node: NodeSpec,
        prefix: str,
        parent: QTreeWidgetItem | None,
        stack: tuple[object, ...],
    ) -> None:
        what = node.op or node.kind.value.replace("_", " ")
        label = f"{node.name} ({what})" if node.name else what
        row = QTreeWidgetItem(parent if parent is not None else self.tree, [label, ""])
        runtime_id = f"{prefix}{node.id}"
        row.setData(0, Qt.ItemDataRole.UserRole, runtime_id)
        self._rows[runtime_id] = row
        for child in node.children:
            self._add(plan, child, prefix, row, stack)
        inner = (
            plan.subtree(node.subtree) if node.kind is NodeKind.SUBTREE and node.subtree else None
        )
        if inner is not None and inner.ref not in stack:
            self._add(plan, inner.tree, f"{runtime_id}/", row, (*stack, inner.ref))

    def set_statuses(self, statuses: dict[str, Status] | None) -> None:
        """Statuses of the nodes inside instances (None: a new run, all back to none)."""
        if statuses is None:
            self._statuses = {}
            for row in self._rows.values():
                row.setText(1, "")
                row.setBackground(1, QBrush())
            return
        self._statuses.update(statuses)
        for runtime_id, status in statuses.items():
            self._colour(runtime_id, status)

    def _colour(self, runtime_id: str, status: Status) -> None:
        row = self._rows.get(runtime_id)
        if row is not None:
            row.setText(1, status.value)
            row.setBackground(1, QBrush(QColor(*STATUS_COLOURS[status])))

    def status_texts(self) -> dict[str, str]:
        """Row label -> status text, for the rows shown (what a user reads)."""
        return {row.text(0): row.text(1) for row in self._rows.values()}
