"""The parent -> child link: NodeGraphQt's PipeItem drawn as a plain elbow.

``PipeItem.draw_path`` asks the viewer for its layout settings and places a direction arrow
(three ``pointAtPercent`` calls) on every redraw; a tree link always runs from a parent's
bottom port down to a child's top port, so this one draws the elbow directly.
"""

from __future__ import annotations

from typing import Any

from NodeGraphQt.qgraphics.pipe import PipeItem
from PySide6.QtCore import QPointF
from PySide6.QtGui import QPainterPath

__all__ = ["TreePipe"]


class TreePipe(PipeItem):
    """A link between two ports, drawn as vertical - horizontal - vertical lines."""

    def __init__(self) -> None:
        super().__init__()
        self._dir_pointer.setVisible(False)
        self.overview = False  # zoomed out: the viewer draws all links as one path instead

    def ends_visible(self) -> bool:
        """Whether both linked nodes are shown."""
        ports = (self.input_port, self.output_port)
        return all(port is not None and port.node.isVisible() for port in ports)

    def add_elbow(self, path: QPainterPath) -> None:
        """Append this link's elbow to ``path``."""
        first, second = _centre(self.output_port), _centre(self.input_port)
        middle = (first.y() + second.y()) / 2.0
        path.moveTo(first)
        path.lineTo(first.x(), middle)
        path.lineTo(second.x(), middle)
        path.lineTo(second)

    def _draw_direction_pointer(self) -> None:
        # Links in a top-down tree always point down; no arrow.
        return

    def draw_path(self, start_port: Any, end_port: Any = None, cursor_pos: Any = None) -> None:
        if cursor_pos is not None or start_port is None or end_port is None:
            super().draw_path(start_port, end_port, cursor_pos)
            return
        visible = start_port.node.isVisible() and end_port.node.isVisible() and not self.overview
        self.setVisible(visible)
        if not visible:
            return
        path = QPainterPath()
        self.add_elbow(path)
        self.setPath(path)


def _centre(port: Any) -> QPointF:
    rect = port.boundingRect()
    pos = port.scenePos()
    return QPointF(pos.x() + rect.width() / 2.0, pos.y() + rect.height() / 2.0)
