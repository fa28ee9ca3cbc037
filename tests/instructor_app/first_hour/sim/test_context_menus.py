"""Context menus fit the node: a leaf offers no "Add child" or "Paste as child"; the Add
child menu of a composite offers the robot's operations too.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtWidgets import QMenu

from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window, search_insert


def _texts(menu: QMenu) -> list[str]:
    return [a.text() for a in menu.actions() if not a.isSeparator()]


def _submenu(menu: QMenu, title: str) -> QMenu:
    for action in menu.actions():
        submenu = action.menu()
        if action.text() == title and isinstance(submenu, QMenu):
            return submenu
    raise LookupError(f"no submenu {title!r} in {_texts(menu)}")


def test_menus_fit_the_node(qtbot: Any, fast_sim: CellSession, tmp_path: Path) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    canvas = window.views.canvas
    root = search_insert(qtbot, window, "sequence", "sequence")
    leaf = search_insert(qtbot, window, "open gripper", "gripper.open")

    leaf_menu = canvas.commands.context_menu(leaf, canvas)
    assert "Add child" not in _texts(leaf_menu)
    assert "Paste as child" not in _texts(leaf_menu)
    assert "Delete" in _texts(leaf_menu)

    root_menu = canvas.commands.context_menu(root, canvas)
    assert "Paste as child" in _texts(root_menu)
    add = _submenu(root_menu, "Add child")
    motion = _submenu(add, "Motion")
    move_to = next(a for a in motion.actions() if a.text() == "Move to")
    move_to.trigger()
    children = window.document.node(root).children
    assert [c.op for c in children] == ["gripper.open", "motion.move_to"]
