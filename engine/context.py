"""What every node of one running tree shares: blackboard, clock, wake-up, event sink."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from engine.blackboard import Blackboard

if TYPE_CHECKING:
    from engine.node import Node
    from engine.status import Status

__all__ = ["TreeContext", "StatusSink", "LogSink"]

StatusSink = Callable[["Node", "Status", "Status"], None]
LogSink = Callable[[str, str], None]


def _no_wake() -> None:
    """Default wake-up when no executor drives the tree: the caller ticks by itself."""


class TreeContext:
    """Per-tree services; one instance per built tree, never shared between trees.

    Attributes:
        blackboard: the tree's parameter store.
        clock: seconds, monotonic; the simulated cell replaces it with simulated time.
        wake: asks the executor for a tick now (an asynchronous job finished).
        status_sink: called on every status change, or None when nobody listens (fast path).
        log_sink: ``(node_id, message)`` lines from operations.
        tick_count: ticks so far, for events.
    """

    __slots__ = ("blackboard", "clock", "log_sink", "status_sink", "tick_count", "wake")

    def __init__(
        self,
        blackboard: Blackboard | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.blackboard = blackboard if blackboard is not None else Blackboard()
        self.clock = clock
        self.wake: Callable[[], None] = _no_wake
        self.status_sink: StatusSink | None = None
        self.log_sink: LogSink | None = None
        self.tick_count = 0
        self.blackboard.count_ticks_with(lambda: self.tick_count)

    def log(self, node_id: str, message: str) -> None:
        sink = self.log_sink
        if sink is not None:
            sink(node_id, message)

    def write(self, key: str, value: Any, writer: str) -> None:
        self.blackboard.set(key, value, writer)
