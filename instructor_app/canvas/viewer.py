"""The canvas's QGraphicsView: NodeGraphQt's viewer with palette drops, the canvas's context
menu and a zoomed-out overview.

Zoomed out (below ``DETAIL_LOD``), a large plan would repaint a thousand link items (each a
cached pixmap) whenever statuses change; there the links are drawn as one path item instead
and the ports (too small to aim at) are hidden. The overview path is rebuilt lazily, at the
next paint after the tree changed.
"""

from __future__ import annotations

from typing import Any

from NodeGraphQt.widgets.viewer import NodeViewer
from PySide6.QtCore import QMimeData, QPoint, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import (
    QColor,
    QContextMenuEvent,
    QDragEnterEvent,
    QDragMoveEvent,
    QDropEvent,
    QFocusEvent,
    QKeyEvent,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPaintEvent,
    QPen,
)
from PySide6.QtWidgets import QGraphicsItem, QGraphicsPathItem, QGraphicsView, QWidget

from instructor_app.canvas.items import DETAIL_LOD, TreeNodeItem, TreePort
from instructor_app.canvas.pipes import TreePipe

__all__ = ["CanvasViewer", "PALETTE_MIME"]

PALETTE_MIME = "application/x-costar-palette-item"


class CanvasViewer(NodeViewer):
    """NodeViewer that accepts palette items and leaves context menus to the canvas.

    Signals:
        palette_dropped(mime, scene_pos): a palette item was dropped.
        context_requested(node_id, global_pos): right click ("" when not on a node).
    """

    palette_dropped = Signal(QMimeData, QPointF)
    context_requested = Signal(str, QPoint)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent, undo_stack=None)
        # NodeGraphQt's choice, kept on purpose: with every node changing status at once,
        # repainting the bounding rect of the changes beats clipping to a region of a
        # thousand small rects (measured 11.5 vs 16 ms a frame for 1000 nodes).
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.BoundingRectViewportUpdate)
        self.pipe_slicing = False
        self._overview_mode = False
        self._links_dirty = True
        self._overview = QGraphicsPathItem()
        pen = QPen(QColor(190, 190, 190), 1.0)
        pen.setCosmetic(True)
        self._overview.setPen(pen)
        self._overview.setZValue(-1)
        self._overview.setVisible(False)
        self.scene().addItem(self._overview)

    # ------------------------------------------------------------------ drops

    def dragEnterEvent(self, event: QDragEnterEvent) -> None:
        self._accept_palette_drag(event)

    def dragMoveEvent(self, event: QDragMoveEvent) -> None:
        self._accept_palette_drag(event)

    @staticmethod
    def _accept_palette_drag(event: QDragMoveEvent) -> None:
        """An enter event is a move event: both take a palette entry and refuse anything else."""
        if event.mimeData().hasFormat(PALETTE_MIME):
            event.acceptProposedAction()
        else:
            event.ignore()

    def dropEvent(self, event: QDropEvent) -> None:
        if not event.mimeData().hasFormat(PALETTE_MIME):
            event.ignore()
            return
        event.setDropAction(Qt.DropAction.CopyAction)
        event.accept()
        self.palette_dropped.emit(event.mimeData(), self.mapToScene(event.position().toPoint()))

    # ------------------------------------------------------------------ menus

    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        self.RMB_state = False
        item = self.node_item_at(self.mapToScene(event.pos()))
        self.context_requested.emit(item.id if item is not None else "", event.globalPos())
        event.accept()

    # ------------------------------------------------------------------ modifiers

    # NodeGraphQt decides what a click does (select, Ctrl: deselect, Shift: extend, Alt: pan)
    # from ALT_state / CTRL_state / SHIFT_state, which only its key events set. A modifier's
    # own key events do not say reliably whether it is still held, and its release may go to
    # another widget (a shortcut, a dock taking the focus): a stale Ctrl made the next click
    # deselect instead of select. The mouse event's modifiers are what is held now.

    def _sync_modifiers(self, modifiers: Qt.KeyboardModifier) -> None:
        self.ALT_state = bool(modifiers & Qt.KeyboardModifier.AltModifier)
        self.CTRL_state = bool(modifiers & Qt.KeyboardModifier.ControlModifier)
        self.SHIFT_state = bool(modifiers & Qt.KeyboardModifier.ShiftModifier)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        self._sync_modifiers(event.modifiers())
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        self._sync_modifiers(event.modifiers())
        super().mouseMoveEvent(event)

    def focusOutEvent(self, event: QFocusEvent) -> None:
        self._sync_modifiers(Qt.KeyboardModifier.NoModifier)  # the release goes elsewhere
        self._cursor_text.setVisible(False)
        super().focusOutEvent(event)

    def keyPressEvent(self, event: QKeyEvent) -> None:
        super().keyPressEvent(event)
        # NodeGraphQt writes modifier hints ("CTRL: Deselect Nodes") on the canvas and hides
        # them on key release, which never comes when a shortcut opened a dialog: no hints.
        self._cursor_text.setVisible(False)

    def node_item_at(
        self, scene_pos: QPointF, exclude: QGraphicsItem | None = None
    ) -> TreeNodeItem | None:
        """The topmost visible node whose body is under ``scene_pos``."""
        for item in self.scene().items(scene_pos):
            while item is not None and not isinstance(item, TreeNodeItem):
                item = item.parentItem()
            if item is None or item is exclude or not item.isVisible():
                continue
            if item.shape_rect().contains(item.mapFromScene(scene_pos)):
                return item
        return None

    # ------------------------------------------------------------------ where the view looks

    # NodeViewer keeps what it shows in its private ``_scene_range`` (it scrolls and zooms by
    # changing that rect); these two go through it so that its own pan and zoom keep working.

    def centre_on(self, point: QPointF) -> None:
        """Scroll (not zoom) so that ``point`` is in the middle."""
        self._scene_range.translate(point - self._scene_range.center())
        self._update_scene()

    def show_rect(self, rect: QRectF) -> None:
        """Zoom and scroll so that ``rect`` fills the view."""
        self._scene_range = QRectF(rect)
        self._update_scene()

    # ------------------------------------------------------------------ links

    @property
    def overview_mode(self) -> bool:
        """Whether links are drawn as one overview path (zoomed out)."""
        return self._overview_mode

    def mark_links_dirty(self) -> None:
        """The tree's links moved or changed: rebuild the overview before the next paint."""
        self._links_dirty = True
        if self._overview_mode:
            self.viewport().update()

    def _update_scene(self) -> None:
        # NodeViewer's funnel for every zoom and pan.
        super()._update_scene()
        overview = self.transform().m11() < DETAIL_LOD
        if overview is not getattr(
            self, "_overview_mode", overview
        ):  # NodeViewer.__init__ calls us
            self._set_overview(overview)

    def _set_overview(self, overview: bool) -> None:
        self._overview_mode = overview
        self._links_dirty = True
        for item in self.scene().items():
            if isinstance(item, TreePipe):
                item.overview = overview
                item.draw_path(item.input_port, item.output_port)
            elif isinstance(item, TreePort):
                item.setVisible(not overview)
        self._overview.setVisible(overview)
        # Boxes and 1-pixel links gain nothing from antialiasing when zoomed out.
        self.setRenderHint(QPainter.RenderHint.Antialiasing, not overview)

    def paintEvent(self, event: QPaintEvent) -> None:
        if self._overview_mode and self._links_dirty:
            self._links_dirty = False
            path = QPainterPath()
            for item in self.scene().items():
                if isinstance(item, TreePipe) and item.ends_visible():
                    item.add_elbow(path)
            self._overview.setPath(path)
        super().paintEvent(event)

    def establish_connection(self, start_port: Any, end_port: Any) -> None:
        """Draw a link (NodeViewer's, with the cheaper TreePipe)."""
        pipe = TreePipe()
        pipe.overview = self._overview_mode
        self._links_dirty = True
        self.scene().addItem(pipe)
        pipe.set_connections(start_port, end_port)
        pipe.draw_path(pipe.input_port, pipe.output_port)
        if start_port.node.selected or end_port.node.selected:
            pipe.highlight()
