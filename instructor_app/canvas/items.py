"""The canvas's node: a NodeGraphQt ``BaseNode`` whose item draws a plan node.

The item paints all its text itself (title, symbol, operation id, bound parameters, the
child-order badge, the "+N" badge of a collapsed subtree), so that a status change is one
``update()`` of one item and a zoomed-out view of a large plan paints one rectangle per node
(level of detail). The editable title (NodeGraphQt's ``NodeTextItem``) is created only while
the user renames the node: a QGraphicsTextItem per node would cost more than the rest of the
node together.

``TreeNodeItem`` is a NodeGraphQt ``NodeItem`` but does not run ``NodeItem.__init__``
(which loads an icon and creates icon, title, "disabled" overlay and port-label items that a
tree node never shows); the NodeItem methods that would touch those are overridden here.
"""

from __future__ import annotations

from typing import Any

from NodeGraphQt import BaseNode
from NodeGraphQt.qgraphics.node_abstract import AbstractNodeItem
from NodeGraphQt.qgraphics.node_base import NodeItem
from NodeGraphQt.qgraphics.node_text_item import NodeTextItem
from NodeGraphQt.qgraphics.port import CustomPortItem
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import (
    QBrush,
    QColor,
    QFocusEvent,
    QFont,
    QFontMetricsF,
    QKeyEvent,
    QPainter,
    QPainterPath,
    QPen,
)
from PySide6.QtWidgets import (
    QGraphicsItem,
    QGraphicsSceneMouseEvent,
    QStyleOptionGraphicsItem,
    QWidget,
)

from engine.status import Status
from instructor_app.canvas import overview
from instructor_app.canvas.style import HALTED_COLOUR, RGB, STATUS_COLOURS, NodeLook

__all__ = ["TreeNode", "TreeNodeItem", "NODE_WIDTH", "DETAIL_LOD", "PARENT_PORT", "CHILD_PORT"]

NODE_WIDTH = 180.0
DETAIL_LOD = 0.4  # below this zoom: coloured boxes with the title drawn larger (see paint)
PARENT_PORT = "parent"
CHILD_PORT = "children"

_PAD = 6.0
_SYMBOL_W = 34.0
_TITLE_H = 24.0
_LINE_H = 14.0
_BORDER = QColor(70, 70, 70)
_SELECTED = QColor(30, 110, 230)
_BROKEN = QColor(200, 30, 30)
_TEXT = QColor(20, 20, 20)
_BADGE = QColor(60, 60, 60)
_WHITE = QColor(255, 255, 255)
_BREAKPOINT = QColor(200, 30, 30)  # a debugger's red dot
_PAUSED_HERE = QColor(255, 140, 0)
_SELECTED_CHANGE = QGraphicsItem.GraphicsItemChange.ItemSelectedChange
_MOVED = QGraphicsItem.GraphicsItemChange.ItemScenePositionHasChanged
_COLOURS: dict[RGB, QColor] = {}


def _qcolor(rgb: RGB) -> QColor:
    """QColors are cached: painting 1000 nodes must not allocate 1000 colours."""
    colour = _COLOURS.get(rgb)
    if colour is None:
        colour = _COLOURS[rgb] = QColor(*rgb)
    return colour


class _Fonts:
    """Fonts and metrics made once per process (QFont needs a QGuiApplication)."""

    title: QFont
    symbol: QFont
    small: QFont
    title_metrics: QFontMetricsF
    small_metrics: QFontMetricsF
    ready = False

    @classmethod
    def ensure(cls) -> None:
        if cls.ready:
            return
        cls.title, cls.symbol, cls.small = QFont(), QFont(), QFont()
        cls.title.setPointSize(10)
        cls.title.setBold(True)
        cls.symbol.setPointSize(13)
        cls.symbol.setBold(True)
        cls.small.setPointSize(8)
        cls.title_metrics = QFontMetricsF(cls.title)
        cls.small_metrics = QFontMetricsF(cls.small)
        cls.ready = True


def _bounds(width: float, height: float) -> QRectF:
    """The item's bounding rect: badges around the body, room above and below for the
    taller zoomed-out box.
    """
    top = -max(12.0, overview.GROW)
    bottom = height + max(10.0, overview.GROW)
    return QRectF(-12.0, top, width + 14.0, bottom - top)


def paint_port(painter: QPainter, rect: QRectF, info: dict[str, Any]) -> None:
    """Ports are small dots, drawn only when zoomed in enough to aim at them."""
    if painter.worldTransform().m11() < DETAIL_LOD:
        return
    painter.save()
    painter.setPen(QPen(_BORDER, 1.0))
    painter.setBrush(QColor(90, 90, 90) if info["hovered"] else QColor(235, 235, 235))
    painter.drawEllipse(rect.adjusted(3, 3, -3, -3))
    painter.restore()


class TreePort(CustomPortItem):
    """A port whose change hook costs one comparison unless the port moved (Qt calls it for
    every change of every item: tens of times per node while a plan opens).
    """

    def itemChange(self, change: QGraphicsItem.GraphicsItemChange, value: Any) -> Any:
        if change == _MOVED and self._pipes:
            self.redraw_connected_pipes()
        return value


class _TitleEditor(NodeTextItem):
    """NodeGraphQt's title editor, shown only while renaming; it reports the new name
    through ``NodeViewer.node_name_changed`` and then goes away.
    """

    def keyPressEvent(self, event: QKeyEvent) -> None:
        super().keyPressEvent(event)
        if event.key() in (Qt.Key.Key_Return, Qt.Key.Key_Escape):
            self.clearFocus()

    def focusOutEvent(self, event: QFocusEvent) -> None:
        super().focusOutEvent(event)
        node = self.parentItem()
        self.setVisible(False)
        if isinstance(node, TreeNodeItem):
            node.update()


class TreeNodeItem(NodeItem):
    """The QGraphicsItem of one plan node."""

    def __init__(self, name: str = "node", parent: QGraphicsItem | None = None) -> None:
        AbstractNodeItem.__init__(self, name, parent)  # not NodeItem.__init__: see module doc
        _Fonts.ensure()
        # NodeGraphQt caches items as pixmaps; a status change would re-render the cache,
        # which costs more than painting these few shapes directly.
        self.setCacheMode(QGraphicsItem.CacheMode.NoCache)
        self._properties["icon"] = None
        self._input_items: dict[Any, None] = {}
        self._output_items: dict[Any, None] = {}
        self._widgets: dict[str, Any] = {}
        self._proxy_mode = False
        self._editor: _TitleEditor | None = None
        self._text_item = None  # NodeItem's attribute; the editor exists only while renaming
        self.look: NodeLook | None = None
        self.status: Status | None = None
        self.status_tip = ""  # why the node failed in the last run ("error type: message")
        self.halted = False  # it was running when the run was stopped
        self.index_badge = 0  # 1-based place among its parent's children; 0: none
        self.hidden_count = 0  # descendants hidden by collapsing; 0: expanded
        self.breakpoint = False  # the run pauses before it
        self.debug_note = ""  # "skipped", "forced: succeed" ...
        self.paused_here = False  # the run is paused at it
        self._elided = ""
        self._bounds = _bounds(self._width, self._height)

    # ------------------------------------------------------------------ content

    def set_look(self, look: NodeLook) -> None:
        """Show ``look`` (after an edit of the node); resizes and places the ports."""
        self.look = look
        self._properties["name"] = look.title
        room = NODE_WIDTH - (_SYMBOL_W if look.symbol else _PAD) - _PAD
        self._elided = _Fonts.title_metrics.elidedText(
            look.title, Qt.TextElideMode.ElideRight, room
        )
        self._update_tip()
        self.draw_node()

    def _update_tip(self) -> None:
        look = self.look
        if look is None:
            return
        tip = look.title if self._elided != look.title else ""
        if look.broken:
            tip = f"{look.title}\n{look.broken}".strip()
        if self.status_tip:
            tip = f"{look.title}\nFailed: {self.status_tip}"
        elif self.halted:
            tip = f"{look.title}\nHalted: it was running when the run was stopped"
        marks = (["breakpoint"] if self.breakpoint else []) + (
            [self.debug_note] if self.debug_note else []
        )
        if marks:
            tip = f"{tip or look.title}\n{', '.join(marks)}"
        self.setToolTip(tip)

    def set_debug(self, breakpoint: bool, note: str, paused_here: bool) -> None:
        """Show a breakpoint (a red dot), a skip or forced result, the run paused here."""
        if (breakpoint, note, paused_here) != (self.breakpoint, self.debug_note, self.paused_here):
            self.breakpoint, self.debug_note, self.paused_here = breakpoint, note, paused_here
            self._update_tip()
            self.update()

    def set_status_tip(self, text: str) -> None:
        """Show why the node failed in its tooltip ("" clears it)."""
        if text != self.status_tip:
            self.status_tip = text
            self._update_tip()

    def set_status(self, status: Status | None) -> None:
        """Colour the body by ``status`` (None: the category colour); ends a halt."""
        if self.halted:
            self.halted = False
            self._update_tip()
            self.update()
        if status is not self.status:
            self.status = status
            self.update()

    def set_halted(self) -> None:
        """Show that the node was halted by a stop (it keeps its last status)."""
        if not self.halted:
            self.halted = True
            self._update_tip()
            self.update()

    def fill(self) -> RGB:
        """The body's colour: the halt's, the status's, else the category's."""
        if self.halted:
            return HALTED_COLOUR
        if self.status is not None:
            return STATUS_COLOURS[self.status]
        return self.look.fill if self.look is not None else (200, 200, 200)

    def set_badges(self, index: int, hidden: int) -> None:
        if (index, hidden) != (self.index_badge, self.hidden_count):
            self.index_badge, self.hidden_count = index, hidden
            self.update()

    def title_rect(self) -> QRectF:
        left = _SYMBOL_W if self.look is not None and self.look.symbol else _PAD
        return QRectF(left, 2.0, NODE_WIDTH - left - _PAD, _TITLE_H)

    def start_rename(self) -> None:
        """Show the title editor over the title (NodeGraphQt's NodeTextItem)."""
        if self._editor is None:
            self._editor = _TitleEditor(self.name, self)
            self._editor.setFont(_Fonts.title)
            self._editor.setDefaultTextColor(_TEXT)
        editor = self._editor
        editor.setPlainText(self.name)
        editor.setTextWidth(self.title_rect().width())
        editor.setPos(self.title_rect().topLeft() - QPointF(4.0, 2.0))
        editor.setVisible(True)
        editor.set_editable(True)
        editor.setFocus()
        self.update()

    @property
    def text_item(self) -> Any:
        return self._editor

    # ------------------------------------------------------------------ NodeGraphQt hooks

    def add_input(
        self,
        name: str = "input",
        multi_port: bool = False,
        display_name: bool = True,
        locked: bool = False,
        painter_func: Any = None,
    ) -> Any:
        return self._new_port("in", name, multi_port, locked, painter_func)

    def add_output(
        self,
        name: str = "output",
        multi_port: bool = False,
        display_name: bool = True,
        locked: bool = False,
        painter_func: Any = None,
    ) -> Any:
        return self._new_port("out", name, multi_port, locked, painter_func)

    def _new_port(self, kind: str, name: str, multi: bool, locked: bool, painter: Any) -> Any:
        port = TreePort(self, painter or paint_port)
        port.name = name
        port.port_type = kind
        port.multi_connection = multi
        port.display_name = False
        port.locked = locked
        return self._add_port(port)

    def _add_port(self, port: Any) -> Any:
        # NodeItem adds a QGraphicsTextItem label per port; tree ports have no labels.
        if port.port_type == "in":
            self._input_items[port] = None
        else:
            self._output_items[port] = None
        return port

    def post_init(self, viewer: Any = None, pos: Any = None) -> None:
        self.draw_node()

    def draw_node(self) -> None:
        """Size the node from its content and place the ports (no scene-wide update)."""
        look = self.look
        lines = (1 if look is not None and look.subtitle else 0) + (
            len(look.lines) if look is not None else 0
        )
        self.prepareGeometryChange()
        self._width = NODE_WIDTH
        self._height = 2.0 + _TITLE_H + lines * _LINE_H + _PAD
        # Room for the badges that stick out of the body.
        self._bounds = _bounds(self._width, self._height)
        for port in self._input_items:
            rect = port.boundingRect()
            port.setPos((self._width - rect.width()) / 2, -rect.height() / 2)
        for port in self._output_items:
            rect = port.boundingRect()
            port.setPos((self._width - rect.width()) / 2, self._height - rect.height() / 2)
        self.update()

    def itemChange(self, change: QGraphicsItem.GraphicsItemChange, value: Any) -> Any:
        # Qt calls this for every change of every item (dozens per node while building);
        # only selection matters to NodeItem (pipe highlighting).
        if change == _SELECTED_CHANGE:
            return super().itemChange(change, value)
        return value

    def mouseDoubleClickEvent(self, event: QGraphicsSceneMouseEvent) -> None:
        if event.button() == Qt.MouseButton.LeftButton and self.title_rect().contains(event.pos()):
            self.start_rename()
            event.accept()
            return
        viewer = self.viewer()
        if viewer is not None:
            viewer.node_double_clicked.emit(self.id)
        QGraphicsItem.mouseDoubleClickEvent(self, event)

    # NodeItem methods that touch the items this class does not create.
    def align_label(self, h_offset: float = 0.0, v_offset: float = 0.0) -> None:
        return

    def align_icon(self, h_offset: float = 0.0, v_offset: float = 0.0) -> None:
        return

    def auto_switch_mode(self) -> None:
        return

    def set_proxy_mode(self, mode: bool) -> None:
        return

    def _set_text_color(self, color: Any) -> None:
        return

    def _tooltip_disable(self, state: bool) -> None:
        return

    @AbstractNodeItem.name.setter
    def name(self, name: str = "") -> None:
        AbstractNodeItem.name.fset(self, name)
        self.update()

    @AbstractNodeItem.disabled.setter
    def disabled(self, state: bool = False) -> None:
        AbstractNodeItem.disabled.fset(self, state)
        self.update()

    # ------------------------------------------------------------------ painting

    def boundingRect(self) -> QRectF:
        # Qt asks several times per item and frame: computed once per size in draw_node.
        # It leaves room for the taller box of the zoomed-out look (see overview_rect).
        return self._bounds

    def shape(self) -> QPainterPath:
        """Body and badges: what clicks and rubber bands hit (not the overview's room)."""
        path = QPainterPath()
        path.addRect(QRectF(-12.0, -12.0, self._width + 14.0, self._height + 22.0))
        return path

    def shape_rect(self) -> QRectF:
        """The body without the badges (hit tests for drops)."""
        return QRectF(0.0, 0.0, self._width, self._height)

    def paint(
        self, painter: QPainter, option: QStyleOptionGraphicsItem, widget: QWidget | None = None
    ) -> None:
        look = self.look
        fill = _qcolor(self.fill())
        rect = QRectF(0.0, 0.0, self._width, self._height)
        scale = painter.worldTransform().m11()  # the view neither rotates nor shears
        if scale < DETAIL_LOD:
            self._paint_overview(painter, scale, fill)
            return
        painter.save()
        pen = QPen(_SELECTED, 3.0) if self.isSelected() else QPen(_BORDER, 1.0)
        if look is not None and look.broken and not self.isSelected():
            pen = QPen(_BROKEN, 2.5, Qt.PenStyle.DashLine)
        if self.paused_here:
            pen = QPen(_PAUSED_HERE, 5.0)
        painter.setPen(pen)
        painter.setBrush(QBrush(fill))
        painter.drawRoundedRect(rect, 6.0, 6.0)
        if self.status is not None and look is not None:
            # Keep the category visible under the status colour: a stripe on the left.
            painter.fillRect(QRectF(1.5, 6.0, 6.0, self._height - 12.0), _qcolor(look.fill))
        if look is not None:
            self._paint_text(painter, look)
        self._paint_badges(painter)
        painter.restore()

    def overview_rect(self, scale: float) -> QRectF:
        """The box as drawn zoomed out (taller, to hold the title; see canvas.overview)."""
        return overview.box(self._title(), self._width, self._height, scale)

    def _title(self) -> str:
        return self.look.title if self.look is not None else ""

    def _paint_overview(self, painter: QPainter, scale: float, fill: QColor) -> None:
        look = self.look
        selected = self.isSelected()
        overview.paint(
            painter,
            self._title(),
            QRectF(0.0, 0.0, self._width, self._height),
            scale,
            _SELECTED if selected else fill,
            _WHITE if selected else _TEXT,
            _BROKEN if look is not None and look.broken else None,
        )

    def _paint_text(self, painter: QPainter, look: NodeLook) -> None:
        painter.setPen(_TEXT)
        if look.symbol:
            painter.setFont(_Fonts.symbol)
            painter.drawText(
                QRectF(4.0, 2.0, _SYMBOL_W - 4.0, _TITLE_H),
                Qt.AlignmentFlag.AlignCenter,
                look.symbol,
            )
        if self._editor is None or not self._editor.isVisible():
            painter.setFont(_Fonts.title)
            painter.drawText(self.title_rect(), Qt.AlignmentFlag.AlignVCenter, self._elided)
        painter.setFont(_Fonts.small)
        y = 2.0 + _TITLE_H
        texts = ([look.subtitle] if look.subtitle else []) + list(look.lines)
        for text in texts:
            painter.drawText(QRectF(_PAD + 4.0, y, self._width - 2 * _PAD - 4.0, _LINE_H), 0, text)
            y += _LINE_H

    def _paint_badges(self, painter: QPainter) -> None:
        painter.setFont(_Fonts.small)
        if self.index_badge:
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(_BADGE)
            painter.drawEllipse(QPointF(-2.0, -2.0), 9.0, 9.0)
            painter.setPen(_WHITE)
            painter.drawText(
                QRectF(-11.0, -11.0, 18.0, 18.0),
                Qt.AlignmentFlag.AlignCenter,
                str(self.index_badge),
            )
        if self.breakpoint or self.debug_note:
            self._paint_debug(painter)
        if self.hidden_count:
            box = QRectF(self._width - 40.0, self._height - 8.0, 40.0, 16.0)
            painter.setPen(QPen(_BORDER, 1.0))
            painter.setBrush(_WHITE)
            painter.drawRoundedRect(box, 7.0, 7.0)
            painter.setPen(_TEXT)
            painter.drawText(box, Qt.AlignmentFlag.AlignCenter, f"+{self.hidden_count}")

    def _paint_debug(self, painter: QPainter) -> None:
        """The breakpoint's red dot on the top right corner, a skip or forced result below."""
        if self.breakpoint:
            painter.setPen(QPen(_WHITE, 1.5))
            painter.setBrush(_BREAKPOINT)
            painter.drawEllipse(QPointF(self._width - 14.0, -2.0), 8.0, 8.0)
        if self.debug_note:
            width = _Fonts.small_metrics.horizontalAdvance(self.debug_note) + 12.0
            box = QRectF(10.0, self._height - 8.0, width, 16.0)
            painter.setPen(QPen(_BORDER, 1.0))
            painter.setBrush(_PAUSED_HERE)
            painter.drawRoundedRect(box, 7.0, 7.0)
            painter.setPen(_TEXT)
            painter.drawText(box, Qt.AlignmentFlag.AlignCenter, self.debug_note)


class TreeNode(BaseNode):
    """NodeGraphQt node of one plan node; its id is the plan node's id."""

    __identifier__ = "costar.canvas"
    NODE_NAME = "node"

    def __init__(self, leaf: bool = False) -> None:
        super().__init__(TreeNodeItem)
        self.add_input(PARENT_PORT, multi_input=False, display_name=False, painter_func=paint_port)
        if not leaf:
            self.add_output(
                CHILD_PORT, multi_output=True, display_name=False, painter_func=paint_port
            )

    @property
    def item(self) -> TreeNodeItem:
        view: TreeNodeItem = self.view
        return view
