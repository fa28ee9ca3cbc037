"""Signals that end the Instructor (SIGTERM, SIGINT, SIGHUP) end it as its close button does.

Python runs a signal handler only when the interpreter gets control, which Qt's event loop
does not give it while it waits; a socket pair written by the C-level handler
(``signal.set_wakeup_fd``) wakes the loop, and the handler then shuts the window down: the run
stops, the arm halts and the cell closes before the process exits, and unsaved work stays in
its recovery file (nobody is asked to save).
"""

from __future__ import annotations

import signal
import socket
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, QSocketNotifier, QTimer

__all__ = ["STOP_SIGNALS", "quit_on_signals"]

STOP_SIGNALS = ("SIGTERM", "SIGINT", "SIGHUP")  # kill, Ctrl-C, a closed terminal


def quit_on_signals(parent: QObject, quit_: Callable[[], None]) -> Callable[[], None]:
    """Call ``quit_()`` on the Qt thread when a stop signal arrives; returns the undo.

    Args:
        parent: owns the socket notifier (the main window).
        quit_: shuts the application down (from the event loop, never inside the handler).
    """
    reader, writer = socket.socketpair()
    reader.setblocking(False)
    writer.setblocking(False)
    previous_fd = signal.set_wakeup_fd(writer.fileno())
    notifier = QSocketNotifier(reader.fileno(), QSocketNotifier.Type.Read, parent)

    def drain() -> None:  # the bytes only wake the loop; the Python handler has run by now
        try:
            while reader.recv(64):
                pass
        except BlockingIOError:
            pass

    notifier.activated.connect(drain)
    signals = [getattr(signal, name) for name in STOP_SIGNALS if hasattr(signal, name)]
    previous = {signum: signal.getsignal(signum) for signum in signals}

    def on_signal(signum: int, frame: Any) -> None:
        QTimer.singleShot(0, quit_)

    for signum in signals:
        signal.signal(signum, on_signal)

    def restore() -> None:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        signal.set_wakeup_fd(previous_fd)
        notifier.setEnabled(False)
        reader.close()
        writer.close()

    return restore
