"""Command handles: what a cell command returns to the thread that sent it.

A handle is finished exactly once, by the thread that runs the command (the simulated cell's
physics thread, the UR backend's I/O thread) or at once by the sender when the command is
refused. Other threads poll ``done()`` or wait on it; callbacks run on the thread
that finishes the handle.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

__all__ = ["CommandHandle"]

_log = logging.getLogger(__name__)


class CommandHandle:
    """The future result of one command sent to a cell.

    Attributes:
        name: what the command was, for messages ("move_linear").
        ok: None while running, then True (success) or False (failure).
        message: why it failed, or a short note on success.
    """

    def __init__(self, name: str, canceller: Callable[[CommandHandle], None] | None = None) -> None:
        self.name = name
        self.ok: bool | None = None
        self.message = ""
        self._canceller = canceller
        self._event = threading.Event()
        self._lock = threading.Lock()
        self._callbacks: list[Callable[[CommandHandle], None]] = []
        self._cancel_requested = False

    @classmethod
    def failed(cls, name: str, message: str) -> CommandHandle:
        """A handle that is already finished with a failure."""
        handle = cls(name)
        handle.resolve(False, message)
        return handle

    @classmethod
    def succeeded(cls, name: str, message: str = "") -> CommandHandle:
        """A handle that is already finished with success."""
        handle = cls(name)
        handle.resolve(True, message)
        return handle

    def done(self) -> bool:
        """True once the command has finished (either way)."""
        return self._event.is_set()

    @property
    def cancel_requested(self) -> bool:
        """True once ``cancel()`` was called (the backend checks it before starting)."""
        return self._cancel_requested

    def cancel(self) -> None:
        """Ask the cell to stop this command. Idempotent; never raises."""
        with self._lock:
            if self._cancel_requested or self._event.is_set():
                return
            self._cancel_requested = True
            canceller = self._canceller
        if canceller is None:
            self.resolve(False, f"{self.name} cancelled")
            return
        try:
            canceller(self)
        except Exception:
            _log.exception("cancelling %s failed", self.name)
            self.resolve(False, f"{self.name} cancelled")

    def add_done_callback(self, fn: Callable[[CommandHandle], None]) -> None:
        """Call ``fn(handle)`` when finished (at once, on this thread, if already finished)."""
        with self._lock:
            if not self._event.is_set():
                self._callbacks.append(fn)
                return
        self._run_callback(fn)

    def wait(self, timeout: float | None = None) -> bool:
        """Block up to ``timeout`` real-time seconds; True if the command has finished."""
        return self._event.wait(timeout)

    def resolve(self, ok: bool, message: str = "") -> bool:
        """Finish the handle (backend use). Only the first call counts; returns whether it did."""
        with self._lock:
            if self._event.is_set():
                return False
            self.ok = ok
            self.message = message
            self._event.set()
            callbacks, self._callbacks = self._callbacks, []
        for fn in callbacks:
            self._run_callback(fn)
        return True

    def _run_callback(self, fn: Callable[[CommandHandle], None]) -> None:
        try:
            fn(self)
        except Exception:
            _log.exception("done callback of %s raised", self.name)

    def __repr__(self) -> str:
        state = "running" if self.ok is None else ("ok" if self.ok else "failed")
        return f"CommandHandle({self.name!r}, {state}, {self.message!r})"
