"""The start page: shown when the Instructor opens without a plan; New plan, the recent
plans and the shipped examples (each with a picture of its tree) lead to the canvas.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from engine.files import load_plan
from instructor_app.panels.start_page import PREVIEW_SIZE, plan_preview
from instructor_app.runtime.session import CellSession
from tests.instructor_app.conftest import EXAMPLES
from tests.instructor_app.gui_driver import make_window

SHIPPED = sorted(EXAMPLES.glob("*.costar.json"))


def test_start_page_offers_new_plan_and_every_example_with_a_picture(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    page = window.start_page
    assert window.start_page_shown and page.isVisible()
    assert not window.views.canvas.isVisible()
    names = {b.objectName() for b in page.example_buttons}
    assert names == {f"example:{p.name}" for p in SHIPPED} and len(names) >= 3
    for button in page.example_buttons:
        image = button.icon().pixmap(PREVIEW_SIZE).toImage()
        # a picture, not a blank box: many colours (boxes, links, background)
        colours = {image.pixel(x, y) for x in range(0, image.width(), 3)
                   for y in range(0, image.height(), 3)}  # fmt: skip
        assert len(colours) > 4, button.objectName()
    qtbot.mouseClick(page.new_button, Qt.MouseButton.LeftButton)
    assert not window.start_page_shown and window.views.canvas.isVisible()
    assert window.document.plan.tree is None


def test_an_example_opens_from_the_start_page_and_becomes_recent(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    page = window.start_page
    button = next(b for b in page.example_buttons if "figure3_debug" in b.objectName())
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert window.document.path == EXAMPLES / "figure3_debug.costar.json"
    assert window.views.canvas.isVisible()
    window.actions_by_name["start_page"].trigger()
    assert window.start_page_shown
    recent = page.recent_list
    assert recent.count() == 1 and recent.isVisibleTo(page)
    window.document.new()
    window.show_start_page()
    recent.setCurrentRow(0)
    qtbot.keyClick(recent, Qt.Key.Key_Return)
    assert window.document.path == EXAMPLES / "figure3_debug.costar.json"
    assert not window.start_page_shown


def test_preview_follows_the_tree_shape(qapp: Any) -> None:
    wide, deep = load_plan(SHIPPED[0]), load_plan(SHIPPED[0])
    assert deep.tree is not None
    deep.tree.children = deep.tree.children[:1]  # a smaller tree draws differently
    assert plan_preview(wide).toImage() != plan_preview(deep).toImage()
