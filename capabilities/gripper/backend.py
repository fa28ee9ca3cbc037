"""What the gripper capability needs from a cell: a parallel gripper.

The simulated cell's ``SimGripper`` implements it as it is; a real cell wraps its gripper's
driver (e.g. a Robotiq gripper over the UR's tool I/O) the same way.
"""

from __future__ import annotations

from typing import Protocol

from capabilities.jobs import CommandHandleLike

__all__ = ["GRIPPER", "GripperBackend"]

GRIPPER = "gripper"


class GripperBackend(Protocol):
    """A parallel gripper with a closed state and a holding sensor."""

    def open(self) -> CommandHandleLike:
        """Open fully, releasing what is held; the handle finishes when the fingers stop."""
        ...

    def close(self) -> CommandHandleLike:
        """Close until the fingers meet or stall on an object."""
        ...

    def is_closed(self) -> bool:
        """True after a close command."""
        ...

    def is_holding(self) -> bool:
        """Closed, yet the fingers stopped apart: something is between them."""
        ...
