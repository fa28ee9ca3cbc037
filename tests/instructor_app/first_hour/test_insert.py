"""Inserting from the palette: a leaf selected gets a sibling after it, the new node is
selected so that the next insert lines up after it, and the view follows new nodes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import QPointF, Qt
from PySide6.QtWidgets import QApplication

from engine.spec import NodeKind
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window, palette_row, search_insert


def test_inserts_line_up_after_the_selected_leaf_and_the_view_follows(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    canvas = window.views.canvas
    root = search_insert(qtbot, window, "sequence", "sequence")
    assert canvas.selected_ids() == [root]
    first = search_insert(qtbot, window, "succeed", "debug.succeed")  # into the sequence
    assert canvas.selected_ids() == [first]
    # A leaf is selected: the next node goes right after it, no re-click of the parent.
    added = [first]
    for _ in range(24):
        added.append(search_insert(qtbot, window, "succeed", "debug.succeed"))
        assert canvas.selected_ids() == [added[-1]]
        qtbot.waitUntil(lambda: canvas.is_visible_in_view(added[-1]))
    assert [c.id for c in window.document.node(root).children] == added
    # Selecting a leaf in the middle inserts right after it.
    canvas.select(added[3])
    middle = search_insert(qtbot, window, "fail", "debug.fail")
    assert [c.id for c in window.document.node(root).children].index(middle) == 4
    qtbot.waitUntil(lambda: canvas.is_visible_in_view(middle))
    # The first leaves went out of view while the row grew: the view did move.
    assert not canvas.is_visible_in_view(added[0])


def test_the_root_leaf_takes_no_sibling(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    search_insert(qtbot, window, "succeed", "debug.succeed")
    field = window.views.palette.search_field
    field.setText("fail")
    field.returnPressed.emit()
    assert window.document.plan.tree is not None and not window.document.plan.tree.children
    assert "is the root" in window.statusBar().currentMessage()


def _click_body(qtbot: Any, window: Any, node_id: str) -> None:
    """One left click on a free spot of the node's body, through the canvas's viewport."""
    canvas = window.views.canvas
    canvas.center_on(node_id)
    item, viewer = canvas.item(node_id), canvas.viewer
    rect = item.shape_rect()
    spots = [QPointF(rect.left() + 16, rect.bottom() - 6), QPointF(rect.right() - 16, 30.0)]
    points = [viewer.mapFromScene(item.mapToScene(spot)) for spot in spots]
    pos = next(p for p in points if viewer.items(p)[:1] == [item])
    qtbot.mouseClick(viewer.viewport(), Qt.MouseButton.LeftButton, pos=pos)


def test_the_first_click_on_the_canvas_after_another_panel_selects_the_node(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.activateWindow()  # focus moves between the panels only in the active window
    qtbot.waitUntil(lambda: QApplication.activeWindow() is window)
    canvas, viewer = window.views.canvas, window.views.canvas.viewer
    root = search_insert(qtbot, window, "sequence", "sequence")
    selector = search_insert(qtbot, window, "selector", "selector")
    search_insert(qtbot, window, "succeed", "debug.succeed")  # under the selector
    _click_body(qtbot, window, root)
    assert QApplication.focusWidget() is viewer
    # Ctrl pressed and let go on the canvas (a shortcut's modifier): NodeGraphQt tracks the
    # modifiers from its key events, which leave Ctrl "held" here; then another dock.
    qtbot.keyPress(viewer, Qt.Key.Key_Control, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyRelease(viewer, Qt.Key.Key_Control)
    problems = window.views.validation
    qtbot.mouseClick(problems, Qt.MouseButton.LeftButton)
    problems.setFocus(Qt.FocusReason.MouseFocusReason)
    assert QApplication.focusWidget() is not viewer
    _click_body(qtbot, window, selector)  # once
    assert canvas.selected_ids() == [selector] and window.selection == [selector]
    tree = window.views.palette.tree
    tree.setFocus()
    tree.setCurrentItem(palette_row(window, "force_failure"))
    qtbot.keyClick(tree, Qt.Key.Key_Return)
    children = window.document.node(selector).children
    assert len(children) == 2 and children[1].kind is NodeKind.FORCE_FAILURE
