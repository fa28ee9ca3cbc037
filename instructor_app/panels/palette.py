"""The palette: the paper's sidebar of logic nodes and capability operations (Figure 5, 2).

Items come from :func:`instructor_app.node_factory.palette_items`, so a new capability shows
up by itself. Typing in the search field replaces the grouped list by the hits, ranked by how
well the label matches and how relevant the capability is (see :func:`search_rank`), each
with its capability beside it; Up/Down move through the hits and Enter inserts the current
one ("search-to-insert"). Double-click or Enter on an item inserts it, dragging it onto
the canvas drops it there. Operations the cell cannot run are greyed, with the reason as
tooltip, and cannot be inserted or dragged.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QEvent, QObject, QSize, Qt, Signal
from PySide6.QtGui import QColor, QIcon, QKeyEvent, QPainter, QPixmap
from PySide6.QtWidgets import (
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from engine.operations import OperationKind, OperationSource
from engine.spec import KIND_CATEGORY, Category, NodeKind
from instructor_app.node_factory import PaletteItem, palette_items
from instructor_app.panels.palette_tree import PaletteDragTree

__all__ = ["PalettePanel", "item_colour", "search_rank"]

_ITEM_ROLE = Qt.ItemDataRole.UserRole + 1

_OP_COLOURS = {
    OperationKind.ACTION: "#4a90d9",
    OperationKind.QUERY: "#3fae6a",
    OperationKind.CONDITION: "#e09a2b",
}
_CATEGORY_COLOURS = {
    Category.COMPOSITE: "#8c8c8c",
    Category.DECORATOR: "#9a7fc4",
    Category.LEAF: "#b0b0b0",
}


def item_colour(item: PaletteItem) -> QColor:
    """The colour that tells an item's kind: action, query, condition, or logic category."""
    if item.op_kind is not None:
        return QColor(_OP_COLOURS[item.op_kind])
    return QColor(_CATEGORY_COLOURS[KIND_CATEGORY[item.kind]])


# Capabilities for trying things out rank after those that act on the cell.
_LOW_RELEVANCE_GROUPS = frozenset({"debug", "template"})


def search_rank(item: PaletteItem, text: str) -> tuple[int, int, str] | None:
    """How well ``item`` answers a search (smaller sorts first); None when it does not match.

    The label counts most (the whole label, then its start, then the phrase, then every
    word), then the operation id, then the capability name and the description; items of
    the debug and template capabilities and items the cell cannot run come after the rest
    of their tier.
    """
    if not item.matches(text):
        return None
    query = " ".join(text.lower().split())
    words = query.split()
    label = item.label.lower()
    ident = (item.op or item.kind.value).lower().replace("_", " ")
    if label == query:
        tier = 0
    elif label.startswith(query):
        tier = 1
    elif query in label:
        tier = 2
    elif all(word in label for word in words):
        tier = 3
    elif all(word in ident for word in words):
        tier = 4
    else:
        tier = 5
    penalty = (item.group.lower() in _LOW_RELEVANCE_GROUPS) + 2 * (not item.available)
    return tier, penalty, label


def _capability_title(item: PaletteItem) -> str:
    is_logic = item.kind is not NodeKind.OPERATION
    return item.group if is_logic else item.group.replace("_", " ").capitalize()


def _icon(colour: QColor, round_shape: bool) -> QIcon:
    pixmap = QPixmap(14, 14)
    pixmap.fill(Qt.GlobalColor.transparent)
    painter = QPainter(pixmap)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    painter.setBrush(colour)
    painter.setPen(colour.darker(140))
    if round_shape:
        painter.drawEllipse(1, 1, 12, 12)
    else:
        painter.drawRoundedRect(1, 1, 12, 12, 3, 3)
    painter.end()
    return QIcon(pixmap)


class _PaletteTree(PaletteDragTree):
    """The list itself: drags palette items, inserts on Enter."""

    def drag_payload(self, item: QTreeWidgetItem) -> tuple[dict[str, Any], str] | None:
        chosen = item.data(0, _ITEM_ROLE)
        if chosen is None:
            return None  # a group
        return chosen.payload, chosen.op or chosen.kind.value


class _HitKeys(QObject):
    """Up/Down typed in the search field move through the hits."""

    def __init__(self, hits: QListWidget, parent: QObject) -> None:
        super().__init__(parent)
        self._hits = hits

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() is QEvent.Type.KeyPress and isinstance(event, QKeyEvent):
            step = {Qt.Key.Key_Down: 1, Qt.Key.Key_Up: -1}.get(Qt.Key(event.key()))
            if step is not None and self._hits.count():
                row = max(0, min(self._hits.count() - 1, self._hits.currentRow() + step))
                self._hits.setCurrentRow(row)
                return True
        return False


class PalettePanel(QWidget):
    """The sidebar of insertable nodes.

    Signals:
        item_activated(PaletteItem): the user asked to insert this (available) item.
    """

    item_activated = Signal(object)

    def __init__(
        self, registry: OperationSource | None = None, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.search_field = QLineEdit()
        self.search_field.setPlaceholderText("Search… (↑↓, Enter inserts)")
        self.search_field.setClearButtonEnabled(True)
        self.search_field.textChanged.connect(self._filter)
        self.search_field.returnPressed.connect(self._insert_current_hit)
        self.hits = QListWidget()
        self.hits.setObjectName("PaletteHits")
        self.hits.setIconSize(QSize(14, 14))
        self.hits.itemDoubleClicked.connect(self._activate)
        self.hits.hide()
        self.search_field.installEventFilter(_HitKeys(self.hits, self))
        self.tree = _PaletteTree()
        self.tree.setHeaderHidden(True)
        self.tree.setIconSize(QSize(14, 14))
        self.tree.setDragEnabled(True)
        self.tree.setDragDropMode(QTreeWidget.DragDropMode.DragOnly)
        self.tree.itemDoubleClicked.connect(lambda item, _col: self._activate(item))
        self.tree.item_entered.connect(self._activate)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.search_field)
        layout.addWidget(self.tree)
        layout.addWidget(self.hits)
        self._items: list[PaletteItem] = []
        self._extra: list[PaletteItem] = []
        self._registry: OperationSource | None = None
        if registry is not None:
            self.set_registry(registry)

    # ------------------------------------------------------------------ public

    def set_registry(self, registry: OperationSource) -> None:
        """Rebuild the list from a (new) cell's registry, keeping the search text."""
        self._registry = registry
        self._items = palette_items(registry) + self._extra
        docs = {c.name: c.doc for c in getattr(registry, "capabilities", [])}
        self.tree.clear()
        groups: dict[str, QTreeWidgetItem] = {}
        for item in self._items:
            if item.group not in groups:
                groups[item.group] = self._group_row(item, docs.get(item.group, ""))
            groups[item.group].addChild(self._item_row(item))
        self.tree.expandAll()
        self._filter(self.search_field.text())

    def set_extra_items(self, items: list[PaletteItem]) -> None:
        """Entries beyond the registry's (the library's subtrees), listed after them."""
        self._extra = list(items)
        if self._registry is not None:
            self.set_registry(self._registry)

    def items(self) -> list[PaletteItem]:
        """Every item, shown or filtered out."""
        return list(self._items)

    def visible_items(self) -> list[PaletteItem]:
        """The items shown, in order: the ranked hits while searching, else every item."""
        if self.search_field.text().strip():
            return [self._hit_item(i) for i in range(self.hits.count())]
        return [item for row, item in self._rows() if not row.isHidden()]

    def current_hit(self) -> PaletteItem | None:
        """The hit Enter would insert (None when not searching or nothing matches)."""
        row = self.hits.currentRow()
        return self._hit_item(row) if self.hits.isVisibleTo(self) and row >= 0 else None

    def groups(self) -> list[str]:
        """Titles of the sections, in order."""
        return [group.text(0) for group in self.tree.groups()]

    # ------------------------------------------------------------------ building

    def _group_row(self, item: PaletteItem, doc: str) -> QTreeWidgetItem:
        row = QTreeWidgetItem(self.tree, [_capability_title(item)])
        row.setFlags(Qt.ItemFlag.ItemIsEnabled)
        font = row.font(0)
        font.setBold(True)
        row.setFont(0, font)
        row.setToolTip(0, doc)
        return row

    def _item_row(self, item: PaletteItem) -> QTreeWidgetItem:
        row = QTreeWidgetItem([item.label])
        row.setData(0, _ITEM_ROLE, item)
        row.setIcon(0, _icon(item_colour(item), item.kind is NodeKind.OPERATION))
        tip = _tooltip(item)
        if item.available:
            row.setFlags(
                Qt.ItemFlag.ItemIsEnabled
                | Qt.ItemFlag.ItemIsSelectable
                | Qt.ItemFlag.ItemIsDragEnabled
            )
        else:
            row.setFlags(Qt.ItemFlag.NoItemFlags)
        row.setToolTip(0, tip)
        return row

    def _hit_row(self, item: PaletteItem) -> QListWidgetItem:
        # The capability beside the label: "Object found" of perception and of predicates
        # differ on sight.
        row = QListWidgetItem(f"{item.label}  —  {_capability_title(item)}")
        row.setData(_ITEM_ROLE, item)
        row.setIcon(_icon(item_colour(item), item.kind is NodeKind.OPERATION))
        row.setToolTip(_tooltip(item))
        if not item.available:
            row.setFlags(Qt.ItemFlag.NoItemFlags)
        return row

    def _hit_item(self, index: int) -> PaletteItem:
        row = self.hits.item(index)
        assert row is not None
        item = row.data(_ITEM_ROLE)
        assert isinstance(item, PaletteItem)
        return item

    def _rows(self) -> list[tuple[QTreeWidgetItem, PaletteItem]]:
        return self.tree.leaves(_ITEM_ROLE)

    # ------------------------------------------------------------------ behaviour

    def _filter(self, text: str) -> None:
        searching = bool(text.strip())
        self.tree.setVisible(not searching)
        self.hits.setVisible(searching)
        self.hits.clear()
        if searching:
            ranked = sorted(
                (rank, index, item)
                for index, item in enumerate(self._items)
                if (rank := search_rank(item, text)) is not None
            )
            for _rank, _index, item in ranked:
                self.hits.addItem(self._hit_row(item))
            first_hit = next((i for i, (_r, _n, it) in enumerate(ranked) if it.available), -1)
            self.hits.setCurrentRow(first_hit)
        for row, item in self._rows():
            row.setHidden(not item.matches(text))
        for group in self.tree.groups():
            shown = any(not child.isHidden() for child in self.tree.members(group))
            group.setHidden(not shown)
            if text and shown:
                group.setExpanded(True)
        first = next(
            (row for row, item in self._rows() if not row.isHidden() and item.available), None
        )
        if first is not None and text:
            self.tree.setCurrentItem(first)

    def _insert_current_hit(self) -> None:
        item = self.current_hit()
        if item is not None and item.available:
            self.item_activated.emit(item)

    def _activate(self, row: object) -> None:
        item: object = None
        if isinstance(row, QTreeWidgetItem):
            item = row.data(0, _ITEM_ROLE)
        elif isinstance(row, QListWidgetItem):
            item = row.data(_ITEM_ROLE)
        if isinstance(item, PaletteItem) and item.available:
            self.item_activated.emit(item)


def _tooltip(item: PaletteItem) -> str:
    kind = item.op_kind.value if item.op_kind is not None else "logic"
    tip = f"{item.op or item.kind.value} ({kind}) — {_capability_title(item)}\n{item.doc}"
    return tip if item.available else f"Not available: {item.reason}\n{tip}"
