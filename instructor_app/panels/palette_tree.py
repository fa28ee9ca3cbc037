"""The tree the palette and the library panel share: its items drag onto the canvas as
palette items, Enter chooses the current one, and its rows are read as groups (top level)
of members.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from typing import Any

from PySide6.QtCore import QMimeData, Qt, Signal
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QTreeWidget, QTreeWidgetItem

from instructor_app.node_factory import PALETTE_MIME

__all__ = ["PaletteDragTree"]


class PaletteDragTree(QTreeWidget):
    """Drags the first chosen item with a payload (:meth:`drag_payload`) as ``PALETTE_MIME``.

    Signals:
        item_entered(QTreeWidgetItem): Enter or Return was pressed on the current item.
    """

    item_entered = Signal(object)

    def drag_payload(self, item: QTreeWidgetItem) -> tuple[dict[str, Any], str] | None:
        """The palette payload of an item and its text for other programs; None: no drag."""
        raise NotImplementedError

    def mimeData(self, items: Iterable[QTreeWidgetItem]) -> QMimeData:
        mime = QMimeData()
        chosen = next((p for p in map(self.drag_payload, items) if p is not None), None)
        if chosen is not None:
            payload, text = chosen
            mime.setData(PALETTE_MIME, json.dumps(payload).encode("utf-8"))
            if text:
                mime.setText(text)
        return mime

    def mimeTypes(self) -> list[str]:
        return [PALETTE_MIME]

    def groups(self) -> list[QTreeWidgetItem]:
        """The top-level rows (the palette's groups, the library's folders)."""
        rows = (self.topLevelItem(i) for i in range(self.topLevelItemCount()))
        return [row for row in rows if row is not None]

    @staticmethod
    def members(group: QTreeWidgetItem) -> list[QTreeWidgetItem]:
        """The rows under a top-level row."""
        rows = (group.child(i) for i in range(group.childCount()))
        return [row for row in rows if row is not None]

    def leaves(self, role: int) -> list[tuple[QTreeWidgetItem, Any]]:
        """Every row under a top-level row, with what it holds under ``role``."""
        return [(row, row.data(0, role)) for group in self.groups() for row in self.members(group)]

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Enter) and self.currentItem():
            self.item_entered.emit(self.currentItem())
            return
        super().keyPressEvent(event)
