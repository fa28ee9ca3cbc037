"""Delivers a run's events to its listeners on a thread of their own.

The engine thread only appends to a deque (atomic, no lock on its path); a listener that is
slow (a GUI, a file) or broken (its error is kept in ``errors``) never holds up a tick.
"""

from __future__ import annotations

import collections
import threading

from engine.events import Event, Listener

__all__ = ["Dispatcher"]


class Dispatcher:
    """Delivers queued events to listeners on its own thread."""

    def __init__(self, listeners: list[Listener]) -> None:
        self._listeners = listeners
        self._queue: collections.deque[Event] = collections.deque()
        self._ready = threading.Condition()
        self._closed = False
        self.errors: list[str] = []
        self._thread = threading.Thread(target=self._loop, name="costar-events", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def put(self, event: Event) -> None:
        self._queue.append(event)  # deque.append is atomic: no lock on the engine's path
        if len(self._queue) == 1:
            with self._ready:
                self._ready.notify()

    def close(self) -> None:
        with self._ready:
            self._closed = True
            self._ready.notify()

    def join(self, timeout: float | None = None) -> None:
        if self._thread.is_alive():
            self._thread.join(timeout)

    def _loop(self) -> None:
        while True:
            with self._ready:
                while not self._queue and not self._closed:
                    self._ready.wait(0.1)
                if not self._queue and self._closed:
                    return
            while self._queue:
                event = self._queue.popleft()
                for listener in self._listeners:
                    try:
                        listener(event)
                    except Exception as exc:  # a listener's bug must not stop the others
                        self.errors.append(f"{type(exc).__name__}: {exc}")
