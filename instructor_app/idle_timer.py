"""The one poll timer of the Instructor that slows down while nothing changes.

A cell PC runs other things: a panel that polls the cell (the arm's state, the robot's
status, the 3D scene) polls quickly while something changes and slowly while nothing does,
and the first change makes it quick again.
"""

from __future__ import annotations

from PySide6.QtCore import QObject, QTimer

__all__ = ["IdlePollTimer"]


class IdlePollTimer(QTimer):
    """A QTimer that fires every ``busy_ms`` and, after ``idle_after`` polls in a row that
    found nothing new (:meth:`polled` with False), every ``idle_ms`` until one finds a change.

    Args:
        busy_ms: the interval while something changes.
        idle_ms: the interval while nothing does (at least ``busy_ms``).
        idle_after: how many polls in a row without a change make it idle.
        parent: the Qt parent.
    """

    def __init__(
        self, busy_ms: int, idle_ms: int, idle_after: int, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self.busy_ms = busy_ms
        self.idle_ms = max(busy_ms, idle_ms)
        self.idle_after = idle_after
        self._still = 0  # polls in a row that found nothing new
        self.setInterval(busy_ms)

    @property
    def idle(self) -> bool:
        """True while the timer fires at its idle interval."""
        return self._still >= self.idle_after

    def polled(self, changed: bool) -> None:
        """Say what a poll found: a change makes the timer quick, a run of none slow."""
        self._still = 0 if changed else self._still + 1
        interval = self.idle_ms if self.idle else self.busy_ms
        if interval != self.interval():
            self.setInterval(interval)
