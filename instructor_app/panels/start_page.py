"""The start page: what the Instructor shows when it opens without a plan.

Three ways in: New plan, the recent plans, and the shipped examples, each with a picture of
its tree (drawn from the plan itself by :func:`plan_preview`, so it is always the plan's
real shape) and its description as tooltip.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from pathlib import Path

from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QIcon, QPainter, QPen, QPixmap
from PySide6.QtWidgets import (
    QFrame,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QScrollArea,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from engine.errors import EngineError
from engine.files import load_plan
from engine.spec import PlanSpec
from instructor_app.canvas.layout import LayoutMetrics, tidy_layout
from instructor_app.canvas.style import look_of

__all__ = ["StartPage", "Example", "find_examples", "plan_preview", "PREVIEW_SIZE"]

PREVIEW_SIZE = QSize(260, 150)
_PATH_ROLE = Qt.ItemDataRole.UserRole + 1
_BACKGROUND = QColor(35, 35, 35)
_LINK = QColor(200, 200, 200)
_BORDER = QColor(70, 70, 70)


class Example:
    """A shipped plan: its file, name, description and the picture of its tree."""

    def __init__(self, path: Path, plan: PlanSpec) -> None:
        self.path = path
        self.name = plan.name or path.name.removesuffix(".costar.json")
        self.description = plan.description
        self.plan = plan


def find_examples(folder: Path) -> list[Example]:
    """The plans in ``folder`` (``*.costar.json``) that read, in name order."""
    examples = []
    for path in sorted(folder.glob("*.costar.json")):
        try:
            examples.append(Example(path, load_plan(path)))
        except (EngineError, OSError):
            continue  # a broken example is not offered; `costar validate` reports it
    return examples


def plan_preview(plan: PlanSpec, size: QSize = PREVIEW_SIZE) -> QPixmap:
    """A picture of the plan's tree: its boxes in their canvas colours, linked parent to child,
    laid out as the canvas lays it out, scaled to fit ``size``.
    """
    pixmap = QPixmap(size)
    pixmap.fill(_BACKGROUND)
    positions = tidy_layout(plan.tree, metrics=LayoutMetrics())
    if not positions or plan.tree is None:
        return pixmap
    width, height = LayoutMetrics().node_width, 50.0
    right = max(x for x, _ in positions.values()) + width
    bottom = max(y for _, y in positions.values()) + height
    margin = 8.0
    # Trees are wide and short: the height may stretch (up to 3x) to fill the picture.
    sx = min((size.width() - 2 * margin) / right, (size.height() - 2 * margin) / bottom)
    sy = min(3 * sx, (size.height() - 2 * margin) / bottom)
    dx = (size.width() - right * sx) / 2
    dy = (size.height() - bottom * sy) / 2

    def box(node_id: str) -> QRectF:
        x, y = positions[node_id]
        return QRectF(dx + x * sx, dy + y * sy, width * sx, height * sy)

    painter = QPainter(pixmap)
    painter.setRenderHint(QPainter.RenderHint.Antialiasing)
    painter.setPen(QPen(_LINK, 1.0))
    for _, node in plan.walk():
        for child in node.children:
            if node.id in positions and child.id in positions:
                top, low = box(node.id), box(child.id)
                painter.drawLine(
                    QPointF(top.center().x(), top.bottom()), QPointF(low.center().x(), low.top())
                )
    for _, node in plan.walk():
        if node.id in positions:
            painter.setPen(QPen(_BORDER, 0.5))
            painter.setBrush(QColor(*look_of(node).fill))
            painter.drawRect(box(node.id))
    painter.end()
    return pixmap


class StartPage(QWidget):
    """New plan, recent plans and the shipped examples.

    Args:
        examples: the shipped plans to offer.
        recent: returns the recent files, most recent first (read each time it is shown).

    Signals:
        new_requested(): New plan was pressed.
        open_requested(str): a recent plan or an example was chosen (its path); "" asks for
            a file.
    """

    new_requested = Signal()
    open_requested = Signal(str)

    def __init__(
        self,
        examples: Iterable[Example],
        recent: Callable[[], list[str]],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("StartPage")
        self._recent = recent
        title = QLabel("<h2>CoSTAR Instructor</h2>Teach the robot a task as a behavior tree.")
        self.new_button = QPushButton("New plan")
        self.new_button.clicked.connect(self.new_requested)
        self.open_button = QPushButton("Open…")
        self.open_button.clicked.connect(lambda: self.open_requested.emit(""))
        buttons = QHBoxLayout()
        buttons.addWidget(self.new_button)
        buttons.addWidget(self.open_button)
        buttons.addStretch(1)
        self.recent_list = QListWidget()
        self.recent_list.setObjectName("RecentPlans")
        self.recent_list.setMaximumHeight(160)
        self.recent_list.itemActivated.connect(self._open_item)
        self.recent_list.itemDoubleClicked.connect(self._open_item)
        self.example_buttons: list[QToolButton] = []
        # One row that scrolls sideways: more examples must not widen the window.
        strip = QWidget()
        examples_row = QHBoxLayout(strip)
        examples_row.setContentsMargins(0, 0, 0, 0)
        for example in examples:
            examples_row.addWidget(self._example_button(example))
        examples_row.addStretch(1)
        self.examples_area = QScrollArea()
        self.examples_area.setWidget(strip)
        self.examples_area.setWidgetResizable(True)
        self.examples_area.setFrameShape(QFrame.Shape.NoFrame)
        self.examples_area.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        bar = self.examples_area.horizontalScrollBar().sizeHint().height()
        self.examples_area.setFixedHeight(strip.sizeHint().height() + bar + 4)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(40, 30, 40, 30)
        layout.addWidget(title)
        layout.addLayout(buttons)
        layout.addSpacing(16)
        layout.addWidget(QLabel("<b>Examples</b>"))
        layout.addWidget(self.examples_area)
        layout.addSpacing(16)
        self.recent_title = QLabel("<b>Recent plans</b>")
        layout.addWidget(self.recent_title)
        layout.addWidget(self.recent_list)
        layout.addStretch(1)
        self.refresh()

    def refresh(self) -> None:
        """Read the recent files again (after a save or an open elsewhere)."""
        self.recent_list.clear()
        for path in self._recent():
            item = QListWidgetItem(f"{Path(path).name}    {Path(path).parent}")
            item.setData(_PATH_ROLE, path)
            item.setToolTip(path)
            self.recent_list.addItem(item)
        empty = self.recent_list.count() == 0
        self.recent_list.setHidden(empty)
        self.recent_title.setHidden(empty)

    def _example_button(self, example: Example) -> QToolButton:
        button = QToolButton()
        button.setObjectName(f"example:{example.path.name}")
        button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextUnderIcon)
        button.setIcon(QIcon(plan_preview(example.plan)))
        button.setIconSize(PREVIEW_SIZE)
        button.setText(example.name)
        button.setToolTip(f"{example.description}\n{example.path}".strip())
        button.setAutoRaise(True)
        button.clicked.connect(lambda: self.open_requested.emit(str(example.path)))
        self.example_buttons.append(button)
        return button

    def _open_item(self, item: QListWidgetItem) -> None:
        self.open_requested.emit(str(item.data(_PATH_ROLE)))
