"""Inserting from the palette: a leaf selected gets a sibling after it, the new node is
selected so that the next insert lines up after it, and the view follows new nodes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window, search_insert


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
