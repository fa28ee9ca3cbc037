"""The Library panel: the subtrees of the library folder and of the shipped library.

Folders hold subtrees; the search field keeps those whose name, description, folder or ports
match every word. The preview shows the selected subtree's description, version and date,
inputs and outputs with their types, and its shape (the tree as an outline). Insert (or a
double click, or Enter) asks for an instance where the canvas selection says; a subtree can
be dragged onto the canvas like a palette item; "Find usages" lists the plans of a folder
that use it. Files that could not be read are listed by name under the tree.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSizePolicy,
    QTextBrowser,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from engine.library import Library, LibraryEntry
from engine.spec import NodeKind, NodeSpec, SubtreePort, SubtreeSpec
from engine.subtree_ops import Usage
from instructor_app.panels.palette_tree import PaletteDragTree

__all__ = ["LibraryPanel", "preview_html"]

_ENTRY_ROLE = Qt.ItemDataRole.UserRole + 1


def _outline(node: NodeSpec, depth: int = 0, limit: int = 40) -> list[str]:
    """The tree as indented lines (the subtree's shape), at most ``limit`` lines."""
    what = node.op or node.kind.value.replace("_", " ")
    label = f"{node.name} ({what})" if node.name else what
    lines = [f"{'&nbsp;' * 4 * depth}{html.escape(label)}"]
    for child in node.children:
        if len(lines) >= limit:
            lines.append(f"{'&nbsp;' * 4 * (depth + 1)}...")
            break
        lines += _outline(child, depth + 1, limit - len(lines))
    return lines


def _ports(title: str, ports: Iterable[SubtreePort]) -> str:
    rows = [
        f"<li><b>{html.escape(p.name)}</b>: {p.type.value}"
        + (f" - {html.escape(p.doc)}" if p.doc else "")
        + "</li>"
        for p in ports
    ]
    return (
        f"<p><b>{title}</b></p><ul>{''.join(rows)}</ul>" if rows else f"<p>No {title.lower()}.</p>"
    )


def preview_html(subtree: SubtreeSpec, folder: str = "", shipped: bool = False) -> str:
    """What the preview shows of a subtree."""
    where = f"{folder or 'top folder'}{', shipped' if shipped else ''}"
    return (
        f"<h3>{html.escape(subtree.name)}</h3>"
        f"<p>Version {subtree.version}, {html.escape(subtree.date or 'no date')} ({where})</p>"
        f"<p>{html.escape(subtree.description)}</p>"
        + _ports("Inputs", subtree.inputs)
        + _ports("Outputs", subtree.outputs)
        + (
            f"<p>Shared names: {html.escape(', '.join(subtree.shared_names))}</p>"
            if subtree.shared_names
            else ""
        )
        + "<p><b>Shape</b></p><p><tt>"
        + "<br>".join(_outline(subtree.tree))
        + "</tt></p>"
    )


class _SubtreeTree(PaletteDragTree):
    """The folders and subtrees; a subtree drags as a palette item of kind subtree."""

    def drag_payload(self, item: QTreeWidgetItem) -> tuple[dict[str, Any], str] | None:
        entry = item.data(0, _ENTRY_ROLE)
        if entry is None:
            return None  # a folder
        return {"kind": NodeKind.SUBTREE.value, "op": entry.subtree.id}, ""


class LibraryPanel(QWidget):
    """The subtree library, browsed and searched.

    Signals:
        insert_requested(LibraryEntry): put an instance of it into the plan.
        usages_requested(LibraryEntry): list the plans that use it.
        reload_requested: read the library folder again.
    """

    insert_requested = Signal(object)
    usages_requested = Signal(object)
    reload_requested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.library: Library | None = None
        self.search_field = QLineEdit(self)
        self.search_field.setPlaceholderText("Search subtrees")
        self.search_field.setClearButtonEnabled(True)
        self.search_field.textChanged.connect(self._filter)
        self.tree = _SubtreeTree(self)
        self.tree.setHeaderLabels(["Subtree", "Version"])
        # The names take the width the version leaves; a name still too long says itself
        # whole in its tooltip.
        header = self.tree.header()
        header.setStretchLastSection(False)
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.ResizeToContents)
        self.tree.setDragEnabled(True)
        self.tree.currentItemChanged.connect(self._current_changed)
        self.tree.itemDoubleClicked.connect(lambda item, _col: self._insert(item))
        self.tree.item_entered.connect(self._insert)
        self.preview = QTextBrowser(self)
        self.problems_label = QLabel(self)
        self.problems_label.setWordWrap(True)
        self.problems_label.setStyleSheet("color: #c0392b")
        self.insert_button = QPushButton("Insert", self)
        self.insert_button.clicked.connect(lambda: self._insert(self.tree.currentItem()))
        self.usages_button = QPushButton("Find usages...", self)
        self.usages_button.clicked.connect(self._usages)
        self.reload_button = QPushButton("Reload", self)
        self.reload_button.clicked.connect(self.reload_requested.emit)
        buttons = QHBoxLayout()
        for button in (self.insert_button, self.usages_button, self.reload_button):
            # they may narrow with the dock: the panel must not widen the window
            button.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
            buttons.addWidget(button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.search_field)
        layout.addWidget(self.tree, 2)
        layout.addLayout(buttons)
        layout.addWidget(self.preview, 2)
        layout.addWidget(self.problems_label)
        self._show(None)

    # ------------------------------------------------------------------ public

    def set_library(self, library: Library) -> None:
        """Show a (freshly scanned) library, keeping the search text."""
        self.library = library
        self.tree.clear()
        folders: dict[str, QTreeWidgetItem] = {}
        for entry in sorted(library.entries, key=lambda e: (e.folder, e.subtree.name)):
            title = entry.folder or "(top)"
            if title not in folders:
                folders[title] = QTreeWidgetItem(self.tree, [title, ""])
                folders[title].setFlags(Qt.ItemFlag.ItemIsEnabled)
            row = QTreeWidgetItem(folders[title], [entry.subtree.name, str(entry.subtree.version)])
            row.setData(0, _ENTRY_ROLE, entry)
            about = entry.subtree.description
            row.setToolTip(0, f"{entry.subtree.name}: {about}" if about else entry.subtree.name)
            row.setFlags(
                Qt.ItemFlag.ItemIsEnabled
                | Qt.ItemFlag.ItemIsSelectable
                | Qt.ItemFlag.ItemIsDragEnabled
            )
        self.tree.expandAll()
        self.problems_label.setText(
            "\n".join(f"Skipped: {problem}" for problem in library.problems)
        )
        self.problems_label.setVisible(bool(library.problems))
        self._filter(self.search_field.text())

    def visible_names(self) -> list[str]:
        """Names of the subtrees shown (search applied), in order."""
        return [row.text(0) for row, _ in self._rows() if not row.isHidden()]

    def select(self, name: str) -> None:
        """Make the subtree called ``name`` the current one (shows its preview)."""
        for row, entry in self._rows():
            if entry.subtree.name == name:
                self.tree.setCurrentItem(row)
                return

    def show_usages(self, name: str, usages: Sequence[Usage], problems: Sequence[str]) -> None:
        """List the plans that use a subtree in the preview."""
        rows = "".join(
            f"<li>{html.escape(u.file.name)}: {html.escape(u.path)} (version {u.version})</li>"
            for u in usages
        )
        skipped = "".join(f"<li>skipped: {html.escape(p)}</li>" for p in problems)
        self.preview.setHtml(
            f"<h3>Usages of {html.escape(name)}</h3>"
            + (f"<ul>{rows}</ul>" if rows else "<p>No plan of the folder uses it.</p>")
            + (f"<ul>{skipped}</ul>" if skipped else "")
        )

    def current_entry(self) -> LibraryEntry | None:
        item = self.tree.currentItem()
        return item.data(0, _ENTRY_ROLE) if item is not None else None

    # ------------------------------------------------------------------ inside

    def _rows(self) -> list[tuple[QTreeWidgetItem, LibraryEntry]]:
        return self.tree.leaves(_ENTRY_ROLE)

    def _filter(self, text: str) -> None:
        found = {id(e) for e in self.library.search(text)} if self.library is not None else set()
        for folder in self.tree.groups():
            shown = 0
            for row in self.tree.members(folder):
                hidden = id(row.data(0, _ENTRY_ROLE)) not in found
                row.setHidden(hidden)
                shown += not hidden
            folder.setHidden(shown == 0)

    def _current_changed(self, item: QTreeWidgetItem | None, _old: object = None) -> None:
        self._show(item)

    def _show(self, item: QTreeWidgetItem | None) -> None:
        entry = item.data(0, _ENTRY_ROLE) if item is not None else None
        self.insert_button.setEnabled(entry is not None)
        self.usages_button.setEnabled(entry is not None)
        if entry is None:
            self.preview.setHtml("<p>Select a subtree to see its inputs, outputs and shape.</p>")
            return
        self.preview.setHtml(preview_html(entry.subtree, entry.folder, entry.shipped))

    def _insert(self, item: object) -> None:
        entry = item.data(0, _ENTRY_ROLE) if isinstance(item, QTreeWidgetItem) else None
        if entry is not None:
            self.insert_requested.emit(entry)

    def _usages(self) -> None:
        entry = self.current_entry()
        if entry is not None:
            self.usages_requested.emit(entry)
