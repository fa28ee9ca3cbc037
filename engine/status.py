"""The four statuses of a behavior-tree node."""

from __future__ import annotations

import enum

__all__ = ["Status", "IDLE", "RUNNING", "SUCCESS", "FAILURE"]


class Status(str, enum.Enum):
    """A node's status. IDLE: not started since the last reset."""

    IDLE = "IDLE"
    RUNNING = "RUNNING"
    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"

    @property
    def finished(self) -> bool:
        return self is Status.SUCCESS or self is Status.FAILURE


# Module-level names for the hot paths: `status is SUCCESS` is one global lookup.
IDLE = Status.IDLE
RUNNING = Status.RUNNING
SUCCESS = Status.SUCCESS
FAILURE = Status.FAILURE
