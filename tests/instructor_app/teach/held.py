"""Pressing a held button (jog arrow, Freedrive, Move here) in a test."""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import QApplication

__all__ = ["hold_ready"]


def hold_ready(qtbot: Any, button: Any) -> None:
    """A held button that loses the focus, or whose window is deactivated, is let go (Qt's
    buttons do that: a dead man's switch, and the arm stops). Before pressing: wait until a
    combo's popup is gone and the window is active, and give the button the focus.
    """
    qtbot.waitUntil(lambda: QApplication.activePopupWidget() is None)
    button.window().activateWindow()
    qtbot.waitUntil(button.window().isActiveWindow)
    button.setFocus()
    qtbot.wait(50)  # a deactivation still queued arrives before the press, not during it
