"""What a run reports to those who watch it, without Qt: plain, immutable events."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from engine.status import Status

__all__ = [
    "Event",
    "RunStarted",
    "StatusChanged",
    "BlackboardWritten",
    "LogMessage",
    "RunFinished",
    "RunHeld",
    "RunPaused",
    "Listener",
]


@dataclass(frozen=True, slots=True)
class RunStarted:
    """A run of the plan named ``plan`` started."""

    time: float
    plan: str


@dataclass(frozen=True, slots=True)
class StatusChanged:
    """A node's status changed; ``error`` is the type of a FAILURE (empty otherwise)."""

    tick: int
    node_id: str
    old: Status
    new: Status
    message: str
    time: float
    error: str = ""


@dataclass(frozen=True, slots=True)
class BlackboardWritten:
    """A node wrote ``value`` under ``key`` on the blackboard."""

    tick: int
    key: str
    value: Any
    node_id: str
    time: float


@dataclass(frozen=True, slots=True)
class LogMessage:
    """A node logged ``message``."""

    tick: int
    node_id: str
    message: str
    time: float


@dataclass(frozen=True, slots=True)
class RunFinished:
    """The run ended: ``reason`` is "finished", "stopped", "timeout" or "error"."""

    tick: int
    status: Status
    reason: str
    message: str
    time: float


@dataclass(frozen=True, slots=True)
class RunHeld:
    """The cell cannot act (a protective stop, a lost connection...): the run is held.

    ``reason`` says why in words; an empty reason means the cell is clear again and the run
    goes on from the nodes that were running.
    """

    tick: int
    reason: str
    time: float


@dataclass(frozen=True, slots=True)
class RunPaused:
    """The run paused by itself at a node: a breakpoint, a step or a run to the node.

    ``where`` is "before" (the node is about to start) or "after" (its status just changed);
    ``why`` says so in words. The run goes on when it is resumed or stepped.
    """

    tick: int
    node_id: str
    where: str
    why: str
    time: float


Event = (
    RunStarted | StatusChanged | BlackboardWritten | LogMessage | RunFinished | RunHeld | RunPaused
)
Listener = Callable[[Event], None]
