"""The Instructor's main window on the simulated cell, as the GUI benches measure it.

Import it inside the measurement: the bench scripts choose the Qt platform first.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from PySide6.QtCore import QEventLoop, QSettings, QTimer

from instructor_app.app import HeadlessDialogs
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from instructor_app.settings import AppSettings

__all__ = ["sim_window", "wait"]


def wait(seconds: float) -> None:
    """Let Qt's event loop run for ``seconds`` (the views paint, the feed's frames arrive)."""
    loop = QEventLoop()
    QTimer.singleShot(int(seconds * 1000), loop.quit)
    loop.exec()


@contextmanager
def sim_window(cell: str = "sim") -> Iterator[MainWindow]:
    """The main window on a simulated cell at real time (or on ``cell``: "none"), shown at
    1920 x 1080, its settings and recovery files in a scratch folder (the caller has made the
    QApplication); on leaving, the run, the views and the autosaver are stopped and the cell
    is closed.
    """
    session = CellSession(cell, speed=1.0)
    session.open()
    with tempfile.TemporaryDirectory() as scratch:
        settings = AppSettings(QSettings(str(Path(scratch, "s.ini")), QSettings.Format.IniFormat))
        window = MainWindow(session, settings, HeadlessDialogs(), Path(scratch, "recovery"))
        try:
            window.resize(1920, 1080)
            window.show()
            yield window
        finally:
            window.controller.shutdown()
            window.cell_views.stop()
            window.autosaver.stop()
            window.hide()
            session.close()
