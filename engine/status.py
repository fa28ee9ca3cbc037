"""The statuses of a behavior-tree node: BehaviorTree.CPP's five."""

from __future__ import annotations

import enum

__all__ = ["Status", "IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED"]


class Status(str, enum.Enum):
    """A node's status. IDLE: not started since the last reset.

    SKIPPED: a pre-condition (``skip_if``, ``while``) kept the node from running, or every
    child of a composite was skipped (BehaviorTree.CPP's SKIPPED). Parents go on past it as
    BehaviorTree.CPP's do. Unlike BehaviorTree.CPP, where a skipped node stays IDLE, the node
    keeps SKIPPED until it is reset (it latches, as SUCCESS and FAILURE do), so the canvas
    and the trace show it; it is not :attr:`finished` (neither a success nor a failure).
    """

    IDLE = "IDLE"
    RUNNING = "RUNNING"
    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"
    SKIPPED = "SKIPPED"

    @property
    def finished(self) -> bool:
        return self is Status.SUCCESS or self is Status.FAILURE


# Module-level names for the hot paths: `status is SUCCESS` is one global lookup.
IDLE = Status.IDLE
RUNNING = Status.RUNNING
SUCCESS = Status.SUCCESS
FAILURE = Status.FAILURE
SKIPPED = Status.SKIPPED
