"""The canvas's commands (QActions, context menu): each one is a document edit.

The main window puts the same QAction objects into its Edit menu (``CanvasView.actions()``),
so a command has one implementation and one enabled state.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from PySide6.QtCore import QMimeData, QObject, Qt, Signal
from PySide6.QtGui import QAction, QGuiApplication, QKeySequence
from PySide6.QtWidgets import QMenu, QWidget

from engine.spec import KIND_CATEGORY, Category, NodeKind, NodeLayout, NodeSpec
from instructor_app.canvas.style import default_title
from instructor_app.canvas.sync import has_position
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import SUBTREE_MIME, DocumentError
from instructor_app.document.tree_ops import can_have_child

__all__ = ["CanvasActions", "MenuEntry", "NodeFactory", "default_node_factory", "LOGIC_KINDS"]

NodeFactory = Callable[[NodeKind, "str | None"], NodeSpec]
# A context menu entry: (text, handler), or (text, [(text, handler), ...]) for a submenu.
MenuEntry = tuple[str, "Callable[[], object] | list[tuple[str, Callable[[], object]]]"]

# What "Add child" offers first: every kind but operations (those follow, by capability) and
# subtree instances (those come from the library).
LOGIC_KINDS = tuple(kind for kind in NodeKind if kind not in (NodeKind.OPERATION, NodeKind.SUBTREE))

_SHORTCUTS: dict[str, tuple[str, QKeySequence | QKeySequence.StandardKey | str]] = {
    "delete": ("Delete", QKeySequence.StandardKey.Delete),
    "cut": ("Cut", QKeySequence.StandardKey.Cut),
    "copy": ("Copy", QKeySequence.StandardKey.Copy),
    "paste": ("Paste as child", QKeySequence.StandardKey.Paste),
    "duplicate": ("Duplicate", "Ctrl+D"),
    "move_left": ("Move left", "Ctrl+Left"),
    "move_right": ("Move right", "Ctrl+Right"),
    "toggle_collapse": ("Collapse / expand", "Ctrl+E"),
    "auto_layout": ("Auto layout", "Ctrl+L"),
}


def default_node_factory(kind: NodeKind, op: str | None) -> NodeSpec:
    """A bare node of ``kind`` (and operation ``op``)."""
    return NodeSpec(kind=kind, op=op)


class CanvasActions(QObject):
    """Canvas commands on the document; errors become ``message`` texts, never exceptions.

    Signals:
        message(str): something the user should read (why an edit was refused).
    """

    message = Signal(str)

    def __init__(
        self, document: PlanDocument, owner: QWidget, selected: Callable[[], list[str]]
    ) -> None:
        super().__init__(owner)
        self.document = document
        self.selected = selected
        # capability title -> [(label, operation id)], set from the cell's registry
        self.operations: dict[str, list[tuple[str, str]]] = {}
        self.node_factory: NodeFactory = default_node_factory
        # node id -> (text, handler) entries added by whoever runs the plan ("Resume from
        # this node"; a list of entries for a submenu): the canvas knows no runs; empty when
        # none apply now
        self.run_entries: Callable[[str], list[MenuEntry]] = lambda _: []
        self.actions: dict[str, QAction] = {}
        handlers: dict[str, Callable[[], None]] = {
            "delete": self.delete,
            "cut": self.cut,
            "copy": self.copy,
            "paste": self.paste,
            "duplicate": self.duplicate,
            "move_left": lambda: self.move_sideways(-1),
            "move_right": lambda: self.move_sideways(+1),
            "toggle_collapse": self.toggle_collapse,
            "auto_layout": self.auto_layout,
        }
        for name, (text, shortcut) in _SHORTCUTS.items():
            action = QAction(text, owner)
            action.setObjectName(f"canvas_{name}")
            action.setShortcut(QKeySequence(shortcut))
            # Shortcuts act while the canvas has focus; the main window's menus reuse them.
            action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.triggered.connect(self._guard(handlers[name]))
            owner.addAction(action)
            self.actions[name] = action
        self.update_enabled()
        # Paste follows the plan too: a node that stops taking children, an emptied plan.
        document.plan_changed.connect(self.update_enabled)

    def _guard(self, handler: Callable[[], None]) -> Callable[[], None]:
        def run() -> None:
            try:
                handler()
            except DocumentError as exc:
                self.message.emit(str(exc))

        return run

    def update_enabled(self) -> None:
        """Enable the node commands only when a node is selected; Paste as child when the
        selected node takes a child, or the plan is empty (the pasted nodes become it).
        """
        selected = self.selected()
        has_node = bool(selected)
        plan = self.document.plan
        if selected:
            node = plan.find(selected[0])
            pastes = node is not None and can_have_child(node)
        else:
            pastes = plan.tree is None
        self.actions["paste"].setEnabled(pastes)
        for name in (
            "delete",
            "cut",
            "copy",
            "duplicate",
            "move_left",
            "move_right",
            "toggle_collapse",
        ):
            self.actions[name].setEnabled(has_node)

    # ------------------------------------------------------------------ commands

    def _current(self) -> str:
        ids = self.selected()
        if not ids:
            raise DocumentError("select a node first")
        return ids[0]

    def delete(self) -> None:
        self.document.remove_nodes(self._top_most(self.selected()))

    def copy(self) -> None:
        self._to_clipboard(self.document.subtree_json(self._current()))

    def cut(self) -> None:
        self._to_clipboard(self.document.cut(self._current()))

    def paste(self) -> None:
        mime = QGuiApplication.clipboard().mimeData()
        if mime is not None and mime.hasFormat(SUBTREE_MIME):
            text = bytes(mime.data(SUBTREE_MIME).data()).decode("utf-8")
        else:
            text = QGuiApplication.clipboard().text()
        ids = self.selected()
        if not ids and self.document.plan.tree is not None:
            raise DocumentError("select the node to paste into")
        self.document.paste(text, ids[0] if ids else None)

    def duplicate(self) -> None:
        self.document.duplicate(self._current())

    def move_sideways(self, step: int) -> None:
        """Move the selected node one place left (-1) or right (+1) among its siblings."""
        node_id = self._current()
        parent_id, index, node = self.document.locate(node_id)
        if parent_id is None:
            raise DocumentError("the root node has no siblings to move past")
        siblings = len(self.document.node(parent_id).children)
        target = index + step
        if not 0 <= target < siblings:
            raise DocumentError(
                f"{node.label!r} is already the {'first' if step < 0 else 'last'} child"
            )
        self.document.move_node(node_id, parent_id, target)

    def toggle_collapse(self) -> None:
        node_id = self._current()
        layout = self.document.plan.layout.get(node_id)
        if not self.document.node(node_id).children:
            raise DocumentError("this node has no children to collapse")
        self.document.set_collapsed(node_id, not (layout is not None and layout.collapsed))

    def auto_layout(self) -> None:
        """Forget all hand-placed positions (one undo step); collapsed flags stay."""
        changes: dict[str, NodeLayout | None] = {}
        for node_id, layout in self.document.plan.layout.items():
            if has_position(layout):
                changes[node_id] = NodeLayout(collapsed=True) if layout.collapsed else None
        if not changes:
            self.message.emit("the plan is already laid out automatically")
            return
        self.document.set_layout(changes, "Auto layout")

    def add_child(self, parent_id: str, kind: NodeKind, op: str | None = None) -> str:
        """Add a new node made by the node factory as ``parent_id``'s last child."""
        return self.document.add_node(self.node_factory(kind, op), parent_id)

    # ------------------------------------------------------------------ menus

    def context_menu(self, node_id: str | None, parent: QWidget) -> QMenu:
        """The menu of a right click on ``node_id`` (None: on the empty canvas)."""
        menu = QMenu(parent)
        if node_id is not None:
            takes_child = can_have_child(self.document.node(node_id))
            if takes_child:
                self._add_child_menu(menu.addMenu("Add child"), node_id)
                menu.addSeparator()
            for name in ("delete", "duplicate", "copy", "cut"):
                menu.addAction(self.actions[name])
            if takes_child:
                menu.addAction(self.actions["paste"])
            menu.addSeparator()
            if self.document.node(node_id).children:
                menu.addAction(self.actions["toggle_collapse"])
            for name in ("move_left", "move_right"):
                menu.addAction(self.actions[name])
            entries = self.run_entries(node_id)
            if entries:
                menu.addSeparator()
            for text, handler in entries:
                if isinstance(handler, list):  # a submenu
                    sub = menu.addMenu(text)
                    for sub_text, sub_handler in handler:
                        sub.addAction(sub_text).triggered.connect(sub_handler)
                else:
                    menu.addAction(text).triggered.connect(handler)
        else:
            menu.addAction(self.actions["paste"])
        menu.addSeparator()
        menu.addAction(self.actions["auto_layout"])
        return menu

    def _add_child_menu(self, add_menu: QMenu, node_id: str) -> None:
        """Logic nodes by category, then one submenu of operations per capability."""
        previous: Category | None = None
        for kind in LOGIC_KINDS:
            if previous is not None and KIND_CATEGORY[kind] is not previous:
                add_menu.addSeparator()
            previous = KIND_CATEGORY[kind]
            action = add_menu.addAction(default_title(NodeSpec(kind=kind)))
            action.setData(kind.value)
            action.triggered.connect(self._guard(functools.partial(self._add_to, node_id, kind)))
        if self.operations:
            add_menu.addSeparator()
        for title, ops in self.operations.items():
            group = add_menu.addMenu(title)
            for label, op in ops:
                action = group.addAction(label)
                action.setData(op)
                action.triggered.connect(
                    self._guard(functools.partial(self._add_to, node_id, NodeKind.OPERATION, op))
                )

    def _add_to(self, parent_id: str, kind: NodeKind, op: str | None = None) -> None:
        self.add_child(parent_id, kind, op)

    # ------------------------------------------------------------------ helpers

    def _top_most(self, ids: list[str]) -> list[str]:
        """The selected nodes that are not inside another selected node."""
        chosen = set(ids)
        result = []
        for node_id in ids:
            parent_id, _, _ = self.document.locate(node_id)
            while parent_id is not None and parent_id not in chosen:
                parent_id, _, _ = self.document.locate(parent_id)
            if parent_id is None:
                result.append(node_id)
        return result

    @staticmethod
    def _to_clipboard(text: str) -> None:
        mime = QMimeData()
        mime.setData(SUBTREE_MIME, text.encode("utf-8"))
        mime.setText(text)
        QGuiApplication.clipboard().setMimeData(mime)
