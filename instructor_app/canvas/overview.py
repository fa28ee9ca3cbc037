"""How a node looks zoomed out (below ``items.DETAIL_LOD``): its box and its title alone.

The title is drawn larger in the scene the further the view zooms out, so that it stays
about ``TITLE_PX`` tall on screen, wrapped at word breaks onto ``LINES`` lines and elided to
the box; the box grows in height (by at most ``GROW`` up and down, inside the item's
bounds) to hold it. A zoomed-out plan therefore never shows blank boxes.
"""

from __future__ import annotations

from PySide6.QtCore import QRectF, Qt
from PySide6.QtGui import QColor, QFont, QFontMetricsF, QPainter, QPen

__all__ = ["TITLE_PX", "GROW", "LINES", "box", "lines", "paint"]

TITLE_PX = 11.0  # the title's height on screen when zoomed out: still readable
GROW = 30.0  # how far a zoomed-out box may grow up and down (inside its bounds)
LINES = 2  # a zoomed-out title wraps onto this many lines at most
_LINE = 1.25  # line height, in font heights
_SIDE = 4.0  # space left and right of the title, scene units


def _font(height: float, scale: float) -> QFont:
    font = QFont()
    font.setPointSize(10)
    font.setBold(True)
    most = (height + 2 * GROW) / (_LINE * LINES + 0.3)
    font.setPixelSize(max(1, round(min(TITLE_PX / max(scale, 0.01), most))))
    return font


def lines(title: str, width: float, height: float, scale: float) -> list[str]:
    """``title`` wrapped at word breaks onto at most LINES lines of a box ``width`` wide,
    the last one elided.
    """
    metrics = QFontMetricsF(_font(height, scale))
    room = width - 2 * _SIDE
    result: list[str] = []
    words = title.split()
    while words and len(result) < LINES - 1:
        count = 1
        while (
            count < len(words) and metrics.horizontalAdvance(" ".join(words[: count + 1])) <= room
        ):
            count += 1
        line = " ".join(words[:count])
        if metrics.horizontalAdvance(line) > room:
            break  # one word too long for a line: it is elided on the last line
        result.append(line)
        words = words[count:]
    if words:
        result.append(metrics.elidedText(" ".join(words), Qt.TextElideMode.ElideRight, room))
    return result or [""]


def box(title: str, width: float, height: float, scale: float) -> QRectF:
    """The zoomed-out box of a node whose body is ``width`` x ``height`` (item coordinates)."""
    count = len(lines(title, width, height, scale))
    wanted = TITLE_PX * (_LINE * count + 0.3) / max(scale, 0.01)
    grow = min(GROW, max(0.0, (wanted - height) / 2))
    return QRectF(0.0, -grow, width, height + 2 * grow)


def paint(
    painter: QPainter,
    title: str,
    body: QRectF,
    scale: float,
    fill: QColor,
    ink: QColor,
    broken: QColor | None,
) -> None:
    """Paint the zoomed-out look: the box in ``fill``, the title in ``ink``, and a dashed
    border in ``broken`` for a node that cannot run.
    """
    rect = box(title, body.width(), body.height(), scale)
    painter.fillRect(rect, fill)
    painter.save()
    if broken is not None:
        painter.setPen(QPen(broken, 3.0 / max(scale, 0.05), Qt.PenStyle.DashLine))
        painter.drawRect(rect)
    painter.setFont(_font(body.height(), scale))
    painter.setPen(ink)
    text = "\n".join(lines(title, body.width(), body.height(), scale))
    painter.drawText(rect.adjusted(_SIDE, 0.0, -_SIDE, 0.0), Qt.AlignmentFlag.AlignCenter, text)
    painter.restore()
