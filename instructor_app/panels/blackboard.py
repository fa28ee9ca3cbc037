"""The blackboard of a running plan: each named parameter and its latest value."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from engine.units import format_value

__all__ = ["BlackboardPanel"]


class BlackboardPanel(QWidget):
    """A table of named parameters with live values (poses in mm and degrees)."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.table = QTableWidget(0, 2)
        self.table.setHorizontalHeaderLabels(["Parameter", "Value"])
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.table)
        self._rows: dict[str, int] = {}
        self._values: dict[str, Any] = {}

    def set_value(self, key: str, value: Any) -> None:
        """Show a parameter's new value (adds a row for a new name, in sorted order)."""
        self._values[key] = value
        text = format_value(value)
        if key in self._rows:
            item = self.table.item(self._rows[key], 1)
            if item is not None and item.text() != text:
                item.setText(text)
            return
        row = sum(1 for name in self._rows if name < key)
        self.table.insertRow(row)
        self.table.setItem(row, 0, QTableWidgetItem(key))
        self.table.setItem(row, 1, QTableWidgetItem(text))
        self._rows = {name: i + (1 if i >= row else 0) for name, i in self._rows.items()}
        self._rows[key] = row

    def set_values(self, values: Mapping[str, Any]) -> None:
        """Show several values at once."""
        for key, value in values.items():
            self.set_value(key, value)

    def clear(self) -> None:
        """Forget every parameter (a new run)."""
        self.table.setRowCount(0)
        self._rows.clear()
        self._values.clear()

    def values(self) -> dict[str, Any]:
        """The values shown, by name."""
        return dict(self._values)

    def text_of(self, key: str) -> str:
        """How a parameter's value is shown."""
        item = self.table.item(self._rows[key], 1)
        return item.text() if item is not None else ""
