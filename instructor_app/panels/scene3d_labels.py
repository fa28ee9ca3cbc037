"""The 3D scene's text labels (recognised objects, ground truth, regions, waypoints), laid
out in screen space so that none hides another.

Each label is centred above the screen point of its anchor; where it would overlap a label
already placed (two objects side by side: "kit_bin 88%" over "plate_8_holes 100%"), it goes
up above that one, as a stack. Labels nearest the bottom of the view are placed first, so a
stack grows upward from the object seen lowest. The layout is made again at every frame, from
the camera of that frame, so turning the view never makes labels overlap.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from pyqtgraph.opengl import GLGraphicsItem
from PySide6.QtCore import QRectF
from PySide6.QtGui import QColor, QFont, QFontMetricsF, QPainter

__all__ = ["Label", "LabelsItem", "stack_labels"]

Rect = tuple[float, float, float, float]  # x, y (top left, widget pixels), width, height
ToScreen = Callable[[np.ndarray], tuple[float, float] | None]
GAP_PX = 2.0  # between a label and its anchor, and between stacked labels


@dataclass(frozen=True)
class Label:
    """A text drawn above a point of the world, in an RGBA colour (0-255)."""

    anchor: tuple[float, float, float]
    text: str
    colour: tuple[int, int, int, int] = (230, 230, 230, 255)


def _overlap(a: Rect, b: Rect) -> bool:
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


def stack_labels(
    anchors: Sequence[tuple[float, float] | None], sizes: Sequence[tuple[float, float]]
) -> list[Rect | None]:
    """Screen rectangles of labels of ``sizes`` (w, h) over ``anchors`` (widget pixels; None
    for an anchor behind the eye, which gets no rectangle) that do not intersect each other.
    """
    rects: list[Rect | None] = [None] * len(anchors)
    order = sorted(
        (i for i, a in enumerate(anchors) if a is not None),
        key=lambda i: (-anchors[i][1], anchors[i][0]),  # type: ignore[index]
    )
    placed: list[Rect] = []
    for i in order:
        (x, y), (w, h) = anchors[i], sizes[i]  # type: ignore[misc]
        rect = (x - w / 2.0, y - GAP_PX - h, w, h)
        # Each move goes above the label hit, and only up: it ends within len(placed) moves.
        while (hit := next((p for p in placed if _overlap(rect, p)), None)) is not None:
            rect = (rect[0], hit[1] - GAP_PX - h, w, h)
        placed.append(rect)
        rects[i] = rect
    return rects


class LabelsItem(GLGraphicsItem.GLGraphicsItem):
    """Draws every label of the scene with a painter over the GL frame, laid out by
    :func:`stack_labels` (the view must have ``to_screen(point)``, as ``SceneView`` has).
    """

    def __init__(self) -> None:
        super().__init__()
        self.setGLOptions("additive")
        self.setDepthValue(1000)  # after everything else: labels are never hidden
        self.font = QFont("Helvetica", 11)
        self._groups: dict[str, list[Label]] = {}

    def set_group(self, group: str, labels: Sequence[Label]) -> None:
        """Replace the labels of one group ("objects", "truth", ...)."""
        self._groups[group] = list(labels)
        self.update()

    @property
    def labels(self) -> list[Label]:
        return [label for labels in self._groups.values() for label in labels]

    def layout(self, to_screen: ToScreen | None = None) -> list[tuple[Label, Rect]]:
        """Each visible label and its screen rectangle for the view's camera now."""
        project = to_screen or self.view().to_screen
        labels = self.labels
        metrics = QFontMetricsF(self.font)
        sizes = []
        for label in labels:
            box = metrics.boundingRect(label.text)
            sizes.append((box.width(), box.height()))
        anchors = [project(np.asarray(label.anchor, dtype=float)) for label in labels]
        rects = stack_labels(anchors, sizes)
        return [(label, rect) for label, rect in zip(labels, rects, strict=True) if rect]

    def paint(self) -> None:
        laid_out = self.layout()
        if not laid_out:
            return
        self.setupGLState()
        painter = QPainter(self.view())
        painter.setFont(self.font)
        painter.setRenderHints(
            QPainter.RenderHint.Antialiasing | QPainter.RenderHint.TextAntialiasing
        )
        for label, (x, y, w, h) in laid_out:
            painter.setPen(QColor(*label.colour))
            painter.drawText(QRectF(x, y, w, h), label.text)
        painter.end()
