"""The run log: time-stamped lines, the last few thousand kept."""

from __future__ import annotations

import html
import time
from collections.abc import Callable

from PySide6.QtWidgets import QPlainTextEdit, QVBoxLayout, QWidget

__all__ = ["LogPanel", "LEVEL_COLOURS"]

LEVEL_COLOURS = {"debug": "#888888", "info": "", "warning": "#b8860b", "error": "#c0392b"}


class LogPanel(QWidget):
    """Lines with time and level; older lines drop off after ``max_lines``.

    Args:
        max_lines: how many lines to keep.
        clock: seconds since the epoch (tests give a fixed one).
    """

    def __init__(
        self,
        max_lines: int = 5000,
        clock: Callable[[], float] = time.time,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self._clock = clock
        self.view = QPlainTextEdit()
        self.view.setReadOnly(True)
        self.view.setMaximumBlockCount(max_lines)
        self.view.setUndoRedoEnabled(False)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.view)

    def append(self, text: str, level: str = "info") -> None:
        """Add a line: ``12:03:04.123 WARNING text``."""
        now = self._clock()
        stamp = time.strftime("%H:%M:%S", time.localtime(now)) + f".{int(now * 1000) % 1000:03d}"
        line = f"{stamp} {level.upper():7} {text}"
        colour = LEVEL_COLOURS.get(level, "")
        escaped = html.escape(line).replace("  ", " &nbsp;")
        self.view.appendHtml(
            f'<span style="color:{colour}">{escaped}</span>' if colour else escaped
        )

    def clear(self) -> None:
        self.view.clear()

    def lines(self) -> list[str]:
        """The lines kept, oldest first."""
        text = self.view.toPlainText()
        return text.split("\n") if text else []
