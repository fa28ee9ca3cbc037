"""The blackboard of a running plan: every named parameter by scope, its latest value (poses
in mm and degrees), and which node wrote it last and when.

Scopes: the plan's own names, the names that cross into subtree instances on purpose (a
subtree's shared names) and one scope per subtree instance (its private names, keys
``"label#id6/NAME"``). While a run is paused a value can be changed: double-click it and
or press Enter on it, and type it as it is shown (mm, degrees); text that is not a value of the entry's type is refused
with a message under the table. The panel only says what was typed (``value_edited``); the
run's undo stack sets it (:mod:`instructor_app.runtime.blackboard_edits`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from PySide6.QtCore import QAbstractItemModel, QModelIndex, QPersistentModelIndex, Qt, Signal
from PySide6.QtWidgets import (
    QHeaderView,
    QLabel,
    QLineEdit,
    QStyledItemDelegate,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from engine.blackboard import OPERATOR, BlackboardEntry
from engine.types import ParamType, type_of_value
from engine.units import ShownValueError, format_value, parse_shown

__all__ = ["BlackboardPanel"]

NAME, VALUE, WRITER, TICK, TIME = range(5)
PLAN_SCOPE = "Plan"
SHARED_SCOPE = "Shared names"
_KEY = Qt.ItemDataRole.UserRole
# Writers that are no node: what the panel calls them.
_WRITERS = {
    "plan": "plan (start value)",
    OPERATOR: "you (while paused)",
    "resume": "the last run (resumed)",
}
_PAUSED_HINT = "Paused: double-click a value to change it (mm and degrees); Ctrl+Z undoes it"
_RUNNING_HINT = "Values change as the plan runs; pause the run to change one"


def scope_of(key: str) -> tuple[str, str]:
    """(the scope's prefix, the name in it): ``"Pick#ab12cd/GRASP"`` -> ("Pick#ab12cd/",
    "GRASP"); a top-level key has the prefix "".
    """
    prefix, _, name = key.rpartition("/")
    return (f"{prefix}/" if prefix else ""), name


def scope_title(prefix: str) -> str:
    """What an instance's scope is called: its labels without their ids, "Kit > Pick"."""
    return " > ".join(part.rsplit("#", 1)[0] for part in prefix.rstrip("/").split("/"))


class _ValueDelegate(QStyledItemDelegate):
    """Edits a value as text in the units shown; the panel reads it (and may refuse it)."""

    def __init__(self, panel: BlackboardPanel) -> None:
        super().__init__(panel)
        self._panel = panel

    def setModelData(
        self,
        editor: QWidget,
        model: QAbstractItemModel,
        index: QModelIndex | QPersistentModelIndex,
    ) -> None:
        # Never written into the table: the value comes back from the run once it is set.
        if isinstance(editor, QLineEdit):
            key = index.sibling(index.row(), NAME).data(_KEY)
            self._panel.typed(key, editor.text())


class BlackboardPanel(QWidget):
    """The named parameters of the run, by scope, with their last writer and tick.

    Signals:
        value_edited(str, object): the user typed a valid new value for a key while paused.
    """

    value_edited = Signal(str, object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.tree = QTreeWidget()
        self.tree.setObjectName("BlackboardTree")
        self.tree.setColumnCount(5)
        self.tree.setHeaderLabels(["Parameter", "Value", "Written by", "Tick", "Time"])
        # Widths from the font, never from the contents: a column fitted to its contents is
        # measured again at every change, which a run writing hundreds of names cannot afford.
        header = self.tree.header()
        header.setStretchLastSection(False)
        header.setSectionResizeMode(VALUE, QHeaderView.ResizeMode.Stretch)
        width = self.fontMetrics().horizontalAdvance
        for column, sample in (
            (NAME, "M" * 12),
            (WRITER, "M" * 14),
            (TICK, "0000000"),
            (TIME, "00000.00 s"),
        ):
            header.resizeSection(column, width(sample))
        self.tree.setEditTriggers(QTreeWidget.EditTrigger.NoEditTriggers)
        self.tree.setItemDelegateForColumn(VALUE, _ValueDelegate(self))
        self.tree.itemDoubleClicked.connect(self._double_clicked)
        self.tree.itemActivated.connect(lambda item, _column: self._double_clicked(item, VALUE))
        self.message = QLabel("")
        self.message.setObjectName("BlackboardMessage")
        self.message.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.tree)
        layout.addWidget(self.message)
        self._scopes: dict[str, QTreeWidgetItem] = {}  # scope prefix ("" or "shared") -> item
        self._items: dict[str, QTreeWidgetItem] = {}  # key -> its row
        self._entries: dict[str, BlackboardEntry] = {}
        self._shared: frozenset[str] = frozenset()
        self._writer_name: Callable[[str], str] = lambda node_id: node_id
        self._editable = False

    # ------------------------------------------------------------------ configuration

    def set_writer_names(self, name_of: Callable[[str], str]) -> None:
        """How a writer's node id is shown (the node's name; runtime ids inside instances)."""
        self._writer_name = name_of

    def set_shared_names(self, names: Iterable[str]) -> None:
        """The names that cross scopes (subtrees' shared names): shown in their own scope."""
        self._shared = frozenset(names)

    def set_editable(self, editable: bool) -> None:
        """Values can be changed (a paused run) or not (running, no run)."""
        self._editable = editable
        for item in self._items.values():
            flags = item.flags() | Qt.ItemFlag.ItemIsEditable
            item.setFlags(flags if editable else flags & ~Qt.ItemFlag.ItemIsEditable)
        self.show_message(_PAUSED_HINT if editable else (_RUNNING_HINT if self._items else ""))

    @property
    def editable(self) -> bool:
        return self._editable

    # ------------------------------------------------------------------ values

    def set_entries(self, entries: Iterable[BlackboardEntry]) -> None:
        """Show the newest write of several entries (``time``: seconds since the run started).

        New rows are added as usual; the texts of the rows already there change with the
        model's signals held and one repaint after (a change signal per cell costs more
        than the rest of the update: a run writing hundreds of names would feel it).
        """
        entries = list(entries)
        for entry in entries:
            if entry.key not in self._items:
                self.set_entry(entry)
        model = self.tree.model()
        held = model.blockSignals(True)
        try:
            for entry in entries:
                self.set_entry(entry)
        finally:
            model.blockSignals(held)
        self.tree.viewport().update()

    def set_entry(self, entry: BlackboardEntry) -> None:
        """Show one entry's value, writer, tick and time (adds its row, and its scope's)."""
        self._entries[entry.key] = entry
        item = self._items.get(entry.key) or self._add_row(entry.key)
        writer = _WRITERS.get(entry.writer) or (
            self._writer_name(entry.writer) if entry.writer else ""
        )
        texts = {
            VALUE: format_value(entry.value),
            WRITER: writer,
            TICK: str(entry.tick),
            TIME: f"{entry.time:.2f} s",
        }
        for column, text in texts.items():
            if item.text(column) != text:
                item.setText(column, text)
        item.setToolTip(WRITER, entry.writer)

    def set_value(self, key: str, value: Any) -> None:
        """Show a parameter's new value when its writer is not known."""
        old = self._entries.get(key)
        ptype = old.ptype if old is not None else None
        self.set_entry(BlackboardEntry(key, value, ptype, "", 0, 0.0))

    def set_values(self, values: Mapping[str, Any]) -> None:
        """Show several values at once."""
        for key, value in values.items():
            self.set_value(key, value)

    def clear(self) -> None:
        """Forget every parameter (a new run)."""
        self.tree.clear()
        self._scopes.clear()
        self._items.clear()
        self._entries.clear()
        self.show_message(_PAUSED_HINT if self._editable else "")

    def values(self) -> dict[str, Any]:
        """The values shown, by key."""
        return {key: entry.value for key, entry in self._entries.items()}

    def entry(self, key: str) -> BlackboardEntry:
        """The entry shown for ``key``."""
        return self._entries[key]

    def item(self, key: str) -> QTreeWidgetItem:
        """The row of ``key``."""
        return self._items[key]

    def text_of(self, key: str, column: int = VALUE) -> str:
        """How a parameter is shown (its value; another column when asked)."""
        return self._items[key].text(column)

    def scopes(self) -> list[str]:
        """The scopes shown, in order."""
        root = self.tree.invisibleRootItem()
        return [root.child(i).text(NAME) for i in range(root.childCount())]

    # ------------------------------------------------------------------ editing

    def show_message(self, text: str, error: bool = False) -> None:
        """Say something under the table (in red for a refused value)."""
        self.message.setText(text)
        self.message.setStyleSheet("color: #b3261e;" if error else "")
        self.message.setProperty("error", error)

    def typed(self, key: str, text: str) -> None:
        """The user typed ``text`` as ``key``'s new value: read it in the entry's type and
        say it (``value_edited``), or refuse it with a message.
        """
        entry = self._entries.get(key)
        if entry is None:
            return
        if not self._editable:
            self.show_message(f"Not changed: {key} can be changed only while paused", error=True)
            return
        ptype = entry.ptype
        if ptype is None or ptype is ParamType.ANY:
            ptype = type_of_value(entry.value)
        try:
            value = parse_shown(ptype, text, key)
        except ShownValueError as exc:
            self.show_message(f"Not changed: {exc}", error=True)
            return
        if value != entry.value:
            self.show_message(_PAUSED_HINT)
            self.value_edited.emit(key, value)

    def _double_clicked(self, item: QTreeWidgetItem, column: int) -> None:
        if self._editable and column == VALUE and item.data(NAME, _KEY):
            self.tree.editItem(item, VALUE)

    # ------------------------------------------------------------------ rows

    def _scope_item(self, key: str) -> QTreeWidgetItem:
        prefix, name = scope_of(key)
        scope = "shared" if not prefix and name in self._shared else prefix
        if scope in self._scopes:
            return self._scopes[scope]
        title = {"": PLAN_SCOPE, "shared": SHARED_SCOPE}.get(scope) or scope_title(prefix)
        if any(item.text(NAME) == title for item in self._scopes.values()):
            title = f"{title} ({prefix.rstrip('/').rsplit('#', 1)[-1]})"  # two of one label
        item = QTreeWidgetItem([title])
        item.setFlags(Qt.ItemFlag.ItemIsEnabled)
        item.setToolTip(NAME, prefix or title)
        font = item.font(NAME)
        font.setBold(True)
        item.setFont(NAME, font)
        order = [PLAN_SCOPE, SHARED_SCOPE]
        rank = order.index(title) if title in order else 2
        root = self.tree.invisibleRootItem()
        at = root.childCount()
        for i in range(root.childCount()):
            other = root.child(i).text(NAME)
            other_rank = order.index(other) if other in order else 2
            if (other_rank, other) > (rank, title):
                at = i
                break
        self.tree.insertTopLevelItem(at, item)
        item.setFirstColumnSpanned(True)  # a scope's title takes the whole row
        item.setExpanded(True)
        self._scopes[scope] = item
        return item

    def _add_row(self, key: str) -> QTreeWidgetItem:
        parent = self._scope_item(key)
        _, name = scope_of(key)
        item = QTreeWidgetItem([name])
        item.setData(NAME, _KEY, key)
        item.setToolTip(NAME, key)
        flags = Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable
        item.setFlags(flags | Qt.ItemFlag.ItemIsEditable if self._editable else flags)
        at = sum(1 for i in range(parent.childCount()) if parent.child(i).text(NAME) < name)
        parent.insertChild(at, item)
        self._items[key] = item
        return item
