"""Scripted actors of the simulated cell: a seeded plan carried out on the physics thread.

The simulated worker (``sim/worker.py``) and the wire bender (``sim/bender.py``) are both a
plan drawn once from the scene's seed (events at offsets from the actor's start, sorted) and
a step hook that carries out each event when the simulated time comes, recording what
happened for tests and scores. :class:`ScheduledActor` is that mechanism, once.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any, Generic, Protocol, TypeVar

__all__ = ["Planned", "ScheduledActor"]


class Planned(Protocol):
    """An event of a plan: ``offset`` seconds after the actor starts."""

    @property
    def offset(self) -> float: ...


P = TypeVar("P", bound=Planned)
E = TypeVar("E")


class ScheduledActor(Generic[P, E]):
    """Carries out ``plan`` (sorted by offset) on the physics thread of a SimCell.

    Subclasses implement :meth:`_act` (one planned event, on the physics thread, returning
    what happened) and may override :meth:`_each_step` for what goes on between events
    (a machine's moving arm).

    Args:
        plan: the events, sorted by offset.
    """

    def __init__(self, plan: Sequence[P]) -> None:
        self.plan = list(plan)
        self._lock = threading.Lock()
        self._events: list[E] = []
        self._next = 0
        self._client = -1
        self._cell: Any = None
        self.start_time: float | None = None

    def install(self, cell: Any, start: bool = True) -> None:
        """Join ``cell`` (a SimCell) and, with ``start``, start acting: times count from now
        (simulated). Without it the actor waits for :meth:`start`.
        """

        def attach(client: int) -> None:
            self._client = client
            self._attached(client)
            if start:
                self.start_time = cell.time()

        cell.call(attach)
        self._cell = cell
        cell.add_step_hook(post=self._on_step)

    def start(self) -> None:
        """Start acting now (simulated time) if not started yet (after :meth:`install`)."""
        cell = self._cell
        if cell is None:
            raise RuntimeError("install the actor on a cell before starting it")

        def begin(_client: int) -> None:
            if self.start_time is None:
                self.start_time = cell.time()

        cell.call(begin)

    def uninstall(self) -> None:
        """Stop acting (idempotent)."""
        cell, self._cell = self._cell, None
        if cell is not None:
            cell.remove_step_hook(post=self._on_step)

    def events(self) -> list[E]:
        """What the actor did so far, in order (a copy)."""
        with self._lock:
            return list(self._events)

    def _record(self, event: E) -> None:
        with self._lock:
            self._events.append(event)

    # ------------------------------------------------------------------ physics thread

    def _attached(self, client: int) -> None:
        """Called on the physics thread when the actor starts (override to build bodies)."""

    def _on_step(self, now: float) -> None:
        start = self.start_time
        if start is None:
            return
        while self._next < len(self.plan):
            planned = self.plan[self._next]
            if start + planned.offset > now + 1e-9:
                break
            self._next += 1
            self._record(self._act(planned, now))
        self._each_step(now - start, now)

    def _act(self, planned: P, now: float) -> E:
        raise NotImplementedError

    def _each_step(self, elapsed: float, now: float) -> None:
        """Called after every physics step once the events due are done (override)."""
