"""CanvasView: the plan drawn as a top-down behavior tree (a NodeGraphQt view of the document).

The view mirrors the document (``GraphMirror``) and turns user gestures on the canvas into
document edits (``CanvasActions`` and the slots here); it never changes the plan otherwise,
so undo and redo are the document's.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence

from PySide6.QtCore import QMimeData, QPoint, QPointF, QRectF, Signal
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QVBoxLayout, QWidget

from engine.operations import OperationKind
from engine.spec import NodeKind, NodeLayout
from engine.status import Status
from instructor_app.canvas import ngqt_fast
from instructor_app.canvas.actions import CanvasActions, NodeFactory, default_node_factory
from instructor_app.canvas.items import CHILD_PORT, PARENT_PORT, TreeNodeItem
from instructor_app.canvas.sync import GraphMirror, has_position
from instructor_app.canvas.viewer import PALETTE_MIME, CanvasViewer
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.document.tree_ops import can_have_child

__all__ = ["CanvasView", "PALETTE_MIME", "MIN_FIT_ZOOM"]

# Fit never zooms out further: titles still show as two lines of about 8 characters.
MIN_FIT_ZOOM = 0.25


class CanvasView(QWidget):
    """The canvas: a view of ``document``'s plan tree.

    Signals:
        selection_changed(list): ids of the selected nodes (after any change).
        node_double_clicked(str): a node was double-clicked (not on its title).
        message(str): something the user should read (an edit was refused, and why).
    """

    selection_changed = Signal(list)
    node_double_clicked = Signal(str)
    message = Signal(str)

    def __init__(self, document: PlanDocument, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        self.viewer = CanvasViewer(self)
        self.graph = ngqt_fast.TreeGraph(self.viewer, self)
        self.mirror = GraphMirror(document, self.graph)
        self.commands = CanvasActions(document, self, self.selected_ids)
        self._selection: list[str] = []
        self._statused: set[str] = set()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.viewer)
        self._connect()
        self.mirror.rebuild()
        self.fit_all()

    def _connect(self) -> None:
        doc = self.document
        doc.plan_reset.connect(self._on_reset)
        doc.node_inserted.connect(self.mirror.inserted)
        doc.node_removed.connect(self.mirror.removed)
        doc.node_moved.connect(self.mirror.moved)
        doc.node_changed.connect(self.mirror.changed)
        doc.layout_changed.connect(lambda ids: self.mirror.relayout())
        doc.plan_changed.connect(self.commands.update_enabled)
        viewer = self.viewer
        viewer.scene().selectionChanged.connect(self._on_selection)
        viewer.node_double_clicked.connect(self.node_double_clicked)
        viewer.node_name_changed.connect(self._on_renamed)
        viewer.moved_nodes.connect(self._on_nodes_moved)
        viewer.connection_changed.connect(self._on_connection_changed)
        viewer.palette_dropped.connect(self._on_palette_dropped)
        viewer.context_requested.connect(self._on_context_menu)
        self.commands.message.connect(self.message)

    # ------------------------------------------------------------------ public API

    # (subtree id, parent id or None, object model name or None) -> the new instance's id;
    # set by the library's wiring.
    instance_inserter: Callable[[str, str | None, str | None], str] | None = None

    def set_node_factory(self, factory: NodeFactory | None) -> None:
        """How palette drops and "Add child" make nodes: ``factory(kind, op) -> NodeSpec``."""
        self.commands.node_factory = factory or default_node_factory

    def set_operations(self, groups: Mapping[str, list[tuple[str, str]]]) -> None:
        """What "Add child" offers besides logic nodes: capability title -> [(label, op)]."""
        self.commands.operations = {title: list(ops) for title, ops in groups.items()}

    def set_operation_kinds(self, kinds: Mapping[str, OperationKind]) -> None:
        """Operation id -> kind, so that leaves get their action/query/condition colour."""
        table = dict(kinds)
        self.mirror.op_kind = table.get
        self.mirror.kinds_known = True
        self.mirror.restyle()

    def set_statuses(self, mapping: Mapping[str, Status]) -> None:
        """Recolour the named nodes only (cheap: one item update each, no relayout)."""
        for node_id, item in self._run_state_items(mapping):
            status = mapping[node_id]
            item.set_status(status)
            if status in (Status.RUNNING, Status.SUCCESS, Status.SKIPPED):
                item.set_status_tip("")  # tried again: the old failure is gone

    def set_failure_tips(self, mapping: Mapping[str, str]) -> None:
        """Node id -> "error type: message": shown in the tooltips of the failed nodes."""
        for node_id, item in self._run_state_items(mapping):
            item.set_status_tip(mapping[node_id])

    def failure_tip(self, node_id: str) -> str:
        """Why the node failed in the last run, as its tooltip shows it ("" : it did not)."""
        return self.mirror.nodes[node_id].item.status_tip

    def clear_statuses(self) -> None:
        """Back to the category colours."""
        nodes = self.mirror.nodes
        for node_id in self._statused:
            node = nodes.get(node_id)
            if node is not None:
                node.item.set_status(None)
                node.item.set_status_tip("")
        self._statused.clear()

    def set_halted(self, node_ids: Sequence[str]) -> None:
        """Show the named nodes as halted: they were running when the run was stopped."""
        for _node_id, item in self._run_state_items(node_ids):
            item.set_halted()

    def _run_state_items(self, node_ids: Iterable[str]) -> Iterator[tuple[str, TreeNodeItem]]:
        """The items of the named nodes on the canvas (others are skipped), each remembered
        as showing a run's state, which :meth:`clear_statuses` takes back.
        """
        nodes = self.mirror.nodes
        for node_id in node_ids:
            node = nodes.get(node_id)
            if node is not None:
                self._statused.add(node_id)
                yield node_id, node.item

    def set_debug_marks(
        self, breakpoints: Iterable[str], notes: Mapping[str, str], paused_at: str = ""
    ) -> None:
        """Draw the breakpoints, the skips and forced results (``notes``: id -> "skipped"),
        and the node the run is paused at (""); every other node loses its marks.
        """
        marked = set(breakpoints)
        for node_id, node in self.mirror.nodes.items():
            node.item.set_debug(node_id in marked, notes.get(node_id, ""), node_id == paused_at)

    def debug_marks(self, node_id: str) -> tuple[bool, str, bool]:
        """(breakpoint, note, paused here) as drawn on the node."""
        item = self.item(node_id)
        return item.breakpoint, item.debug_note, item.paused_here

    def is_halted(self, node_id: str) -> bool:
        """True when the node shows as halted by a stop."""
        return self.mirror.nodes[node_id].item.halted

    def fill_of(self, node_id: str) -> tuple[int, int, int]:
        """The node's body colour as painted (halt, status or category)."""
        return self.mirror.nodes[node_id].item.fill()

    def tooltip_of(self, node_id: str) -> str:
        """The node's tooltip."""
        return self.mirror.nodes[node_id].item.toolTip()

    def status_of(self, node_id: str) -> Status | None:
        """The status the node shows (None: none)."""
        return self.mirror.nodes[node_id].item.status

    def selected_ids(self) -> list[str]:
        return [
            item.id
            for item in self.viewer.scene().selectedItems()
            if isinstance(item, TreeNodeItem)
        ]

    def select(self, node_id: str) -> None:
        """Select only ``node_id`` (expanding nothing; a hidden node is not selectable)."""
        node = self.mirror.nodes.get(node_id)
        scene = self.viewer.scene()
        scene.blockSignals(True)  # one selection_changed, not one per deselected node
        try:
            scene.clearSelection()
            if node is not None:
                node.item.setSelected(True)
        finally:
            scene.blockSignals(False)
        self._on_selection()

    def center_on(self, node_id: str) -> None:
        node = self.mirror.nodes.get(node_id)
        if node is not None:
            item = node.item
            self.viewer.centre_on(item.mapToScene(item.shape_rect().center()))

    def ensure_visible(self, node_id: str, margin: float = 40.0) -> None:
        """Scroll (not zoom) so that the node is in view; nothing moves when it already is."""
        node = self.mirror.nodes.get(node_id)
        if node is None:
            return
        item = node.item
        # The mirror may lay the tree out after the insertion signal: place it now.
        rect = item.sceneBoundingRect().adjusted(-margin, -margin, margin, margin)
        visible = self.viewer.mapToScene(self.viewer.viewport().rect()).boundingRect()
        if not visible.contains(rect):
            self.viewer.centre_on(rect.center())

    def is_visible_in_view(self, node_id: str) -> bool:
        """Whether the whole node shows in the viewport (tests, the view following edits)."""
        item = self.mirror.nodes[node_id].item
        visible = self.viewer.mapToScene(self.viewer.viewport().rect()).boundingRect()
        return item.isVisible() and visible.contains(item.sceneBoundingRect())

    def fit_all(self) -> None:
        """Zoom so that the whole tree shows, but not below MIN_FIT_ZOOM, where titles would
        be too small to read: a tree too large for that shows its top, around the root (the
        rest is a scroll away).
        """
        rect = QRectF()
        for node in self.mirror.nodes.values():
            if node.item.isVisible():
                rect = rect.united(node.item.sceneBoundingRect())
        if rect.isNull():
            return
        rect = rect.adjusted(-40, -40, 40, 40)
        port = self.viewer.viewport().rect()
        width, height = port.width() / MIN_FIT_ZOOM, port.height() / MIN_FIT_ZOOM
        # Before it is shown the viewport has no real size yet: show all, the viewer keeps
        # the rect in view when it gets its size.
        if not self.viewer.isVisible() or (rect.width() <= width and rect.height() <= height):
            self.viewer.show_rect(rect)
            return
        root = self.document.plan.tree
        centre = rect.center().x()
        if root is not None and root.id in self.mirror.nodes:
            centre = self.mirror.nodes[root.id].item.sceneBoundingRect().center().x()
        left = min(max(centre - width / 2, rect.left()), max(rect.left(), rect.right() - width))
        self.viewer.show_rect(QRectF(left, rect.top(), width, height))

    def item(self, node_id: str) -> TreeNodeItem:
        """The graphics item of a node (tests, the failing-node display)."""
        return self.mirror.nodes[node_id].item

    def node_count(self) -> int:
        return len(self.mirror.nodes)

    def action(self, name: str) -> QAction:
        """One of the canvas's QActions by role: delete, cut, copy, paste, duplicate,
        move_left, move_right, toggle_collapse, auto_layout (``actions()`` lists them).
        """
        return self.commands.actions[name]

    # ------------------------------------------------------------------ document -> view

    def _on_reset(self) -> None:
        self._statused.clear()
        self.mirror.rebuild()
        self.fit_all()

    def _on_selection(self) -> None:
        ids = self.selected_ids()
        if ids != self._selection:
            self._selection = ids
            self.commands.update_enabled()
            self.selection_changed.emit(list(ids))

    # ------------------------------------------------------------------ user gestures -> document

    def _on_renamed(self, node_id: str, name: str) -> None:
        try:
            spec = self.document.node(node_id)
            # The title shows the kind or operation when unnamed; keeping it is no rename.
            if name != spec.label or spec.name:
                self.document.rename(node_id, name)
        except DocumentError as exc:
            self.message.emit(str(exc))
        self.mirror.changed(node_id)

    def _on_nodes_moved(self, moved: dict[object, list[float]]) -> None:
        items = [item for item in moved if isinstance(item, TreeNodeItem)]
        if len(items) == 1:
            body = items[0].mapToScene(items[0].shape_rect().center())
            target = self.viewer.node_item_at(body, exclude=items[0])
            if target is not None:
                self._reparent(items[0].id, target.id)
                return
        layouts: dict[str, NodeLayout | None] = {}
        for item in items:
            old = self.document.plan.layout.get(item.id)
            layouts[item.id] = NodeLayout(
                item.pos().x(), item.pos().y(), old is not None and old.collapsed
            )
        if layouts:
            self.document.set_layout(layouts, "Move nodes" if len(layouts) > 1 else "Move node")

    def _reparent(self, node_id: str, parent_id: str) -> None:
        """Make ``node_id`` the last child of ``parent_id`` (a drag onto a node, a new link);
        its hand-placed position goes with the same undo step.
        """
        doc = self.document
        try:
            placed = doc.plan.layout.get(node_id)
            layouts: dict[str, NodeLayout | None] = {}
            if has_position(placed):
                layouts[node_id] = (
                    NodeLayout(collapsed=True) if placed and placed.collapsed else None
                )
            doc.move_to_end(node_id, parent_id, layouts)
        except DocumentError as exc:
            self.message.emit(str(exc))
        self.mirror.restore_link(node_id)
        self.mirror.relayout()

    def _on_connection_changed(self, disconnected: list, connected: list) -> None:
        touched = {port.node.id for pair in disconnected + connected for port in pair}
        for first, second in connected:
            child, parent = (first, second) if first.name == PARENT_PORT else (second, first)
            if child.name == PARENT_PORT and parent.name == CHILD_PORT:
                self._reparent(child.node.id, parent.node.id)
                break
        else:
            if disconnected:
                self.message.emit("every node needs its parent: drag the link onto another node")
        for node_id in touched:  # the viewer may have deleted pipes of refused changes
            if node_id in self.mirror.nodes:
                self.mirror.restore_link(node_id)

    def _on_palette_dropped(self, mime: QMimeData, scene_pos: QPointF) -> None:
        try:
            data = json.loads(bytes(mime.data(PALETTE_MIME).data()).decode("utf-8"))
            kind = NodeKind(data["kind"])
            op = data.get("op")
            dropped_object = data.get("object")  # an object model dragged: Pick it
        except (ValueError, KeyError, TypeError, AttributeError) as exc:
            self.message.emit(f"cannot drop this item: {exc}")
            return
        target = self.viewer.node_item_at(scene_pos)
        try:
            if kind is NodeKind.SUBTREE:  # a library subtree: its instance comes with it
                if self.instance_inserter is None or not op:
                    raise DocumentError("this canvas has no subtree library")
                if target is None and self.document.plan.tree is not None:
                    raise DocumentError("drop the subtree onto the node that should hold it")
                parent_id = target.id if target else None
                self.select(self.instance_inserter(op, parent_id, dropped_object))
            elif target is not None:
                if not can_have_child(self.document.node(target.id)):
                    raise DocumentError(
                        f"{self.document.node(target.id).label!r} cannot take a child"
                    )
                self.select(self.commands.add_child(target.id, kind, op))
            elif self.document.plan.tree is None:
                node_id = self.document.add_node(self.commands.node_factory(kind, op))
                self.select(node_id)
                self.fit_all()
            else:
                raise DocumentError("drop the node onto the node that should hold it")
        except DocumentError as exc:
            self.message.emit(str(exc))

    def _on_context_menu(self, node_id: str, global_pos: QPoint) -> None:
        if node_id and node_id not in self.selected_ids():
            self.select(node_id)
        menu = self.commands.context_menu(node_id or None, self)
        menu.exec(global_pos)
