"""Executor events -> batches for the GUI thread.

The executor delivers events on its dispatcher thread; :meth:`EventPump.put` is that thread's
only entry point and just appends to a deque (atomic in CPython: no lock on the engine's
path). The GUI thread calls :meth:`EventPump.drain` from a timer and gets one
:class:`Batch`: the newest status per node, the newest blackboard value per key, every log
line, and the RunFinished event if the run ended. No Qt here, so it is tested on its own.
"""

from __future__ import annotations

import collections
from dataclasses import dataclass, field
from typing import Any

from engine.error_types import ErrorType
from engine.events import (
    BlackboardWritten,
    Event,
    LogMessage,
    RunFinished,
    RunHeld,
    RunPaused,
    RunStarted,
    StatusChanged,
)
from engine.status import Status

__all__ = ["Batch", "EventPump", "failure_text"]


def failure_text(error: str, message: str) -> str:
    """A failure as the Instructor shows it: ``"grasp_failed: the cup is not held"``.

    The untyped ``failed`` is left out: it says nothing the status does not.
    """
    kind = "" if error == ErrorType.FAILED.value else error
    return ": ".join(part for part in (kind, message) if part)


@dataclass
class Batch:
    """What happened since the last drain.

    Attributes:
        statuses: node id -> newest status (only nodes that changed).
        messages: node id -> the message that came with its newest status.
        failures: (node id, message, error type) of the nodes that turned FAILURE, in the
            order they did (a node that failed and was reset in the same batch is still
            here: its failure was real).
        writes: blackboard key -> newest value, in order of first write.
        written: blackboard key -> its newest write (writer, tick, time), same order.
        logs: (node id, message) in order.
        finished: the RunFinished event, if the run ended.
        started: whether a RunStarted event arrived.
        holds: why the cell held the run, in order ("" when it went on again).
        idled: nodes that went from RUNNING to IDLE (halted: by a hold, a stop, a parent).
        paused: where the run paused by itself last (a breakpoint, a step), if it did.
    """

    statuses: dict[str, Status] = field(default_factory=dict)
    messages: dict[str, str] = field(default_factory=dict)
    failures: list[tuple[str, str, str]] = field(default_factory=list)
    writes: dict[str, Any] = field(default_factory=dict)
    written: dict[str, BlackboardWritten] = field(default_factory=dict)
    logs: list[tuple[str, str]] = field(default_factory=list)
    finished: RunFinished | None = None
    started: bool = False
    holds: list[str] = field(default_factory=list)
    idled: set[str] = field(default_factory=set)
    paused: RunPaused | None = None

    @property
    def empty(self) -> bool:
        return not (
            self.statuses
            or self.writes
            or self.logs
            or self.finished
            or self.started
            or self.holds
            or self.paused
        )


class EventPump:
    """A thread-safe mailbox of engine events, drained in batches."""

    def __init__(self) -> None:
        self._queue: collections.deque[Event] = collections.deque()

    def put(self, event: Event) -> None:
        """Any thread (the executor's dispatcher): queue one event."""
        self._queue.append(event)

    def __len__(self) -> int:
        return len(self._queue)

    def drain(self) -> Batch:
        """The GUI thread: take everything queued so far, coalesced."""
        batch = Batch()
        while True:
            try:
                event = self._queue.popleft()
            except IndexError:
                return batch
            _merge(batch, event)


def _merge(batch: Batch, event: Event) -> None:
    if isinstance(event, StatusChanged):
        batch.statuses[event.node_id] = event.new
        batch.messages[event.node_id] = event.message
        if event.old is Status.RUNNING and event.new is Status.IDLE:
            batch.idled.add(event.node_id)
        elif event.new is not Status.IDLE:
            batch.idled.discard(event.node_id)
        if event.new is Status.FAILURE:
            batch.failures.append((event.node_id, event.message, event.error))
    elif isinstance(event, BlackboardWritten):
        batch.writes[event.key] = event.value
        batch.written[event.key] = event
    elif isinstance(event, LogMessage):
        batch.logs.append((event.node_id, event.message))
    elif isinstance(event, RunFinished):
        batch.finished = event
    elif isinstance(event, RunStarted):
        batch.started = True
    elif isinstance(event, RunHeld):
        batch.holds.append(event.reason)
    elif isinstance(event, RunPaused):
        batch.paused = event
