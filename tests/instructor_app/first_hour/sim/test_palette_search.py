"""Palette search on the simulated cell: ranked by label and capability, Up/Down through the
hits, the capability beside each hit, Enter inserts the current hit.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window


def test_search_move_to_then_enter_inserts_motion_move_to(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    palette = window.views.palette
    qtbot.keyClicks(palette.search_field, "move to")
    hits = palette.visible_items()
    assert hits[0].op == "motion.move_to", [h.op for h in hits]
    ops = [h.op for h in hits]
    assert ops.index("motion.move_to") < ops.index("debug.pretend_move")
    # the capability is shown beside each hit
    assert palette.hits.item(0).text() == "Move to  —  Motion"
    # Down moves to the next hit, Up back
    qtbot.keyClick(palette.search_field, Qt.Key.Key_Down)
    assert palette.current_hit() == hits[1]
    qtbot.keyClick(palette.search_field, Qt.Key.Key_Up)
    assert palette.current_hit() == hits[0]
    qtbot.keyClick(palette.search_field, Qt.Key.Key_Return)
    tree = window.document.plan.tree
    assert tree is not None and tree.op == "motion.move_to"


def test_same_label_in_two_capabilities_differs_on_sight(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    palette = window.views.palette
    qtbot.keyClicks(palette.search_field, "object found")
    texts = [palette.hits.item(i).text() for i in range(palette.hits.count())]
    found = [t for t in texts if t.startswith("Object found  —  ")]
    assert len(found) >= 2 and len(set(found)) == len(found), texts
