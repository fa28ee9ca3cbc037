"""What the gripper capability needs from a cell: a parallel gripper (and a held suction tool).

The simulated cell's ``SimGripper`` implements it as it is; a real cell wraps its gripper's
driver (e.g. a Robotiq gripper over the UR's tool I/O) the same way. A grasp made with the
suction tool reads the tool through :class:`HeldSuctionTool`, the part of the tool
capability's ``SuctionBackend`` it needs (the tool capability builds on this one, never the
other way round).
"""

from __future__ import annotations

from typing import Protocol

from capabilities.jobs import CommandHandleLike

__all__ = ["GRIPPER", "SUCTION", "GripperBackend", "HeldSuctionTool"]

GRIPPER = "gripper"
SUCTION = "suction"


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


class HeldSuctionTool(Protocol):
    """The suction tool as a grasp uses it, when the gripper holds it (interface ``suction``)."""

    def suction_on(self) -> CommandHandleLike:
        """Switch the vacuum on (fails when the tool is not in the gripper)."""
        ...

    def has_part(self) -> bool:
        """The vacuum sensor: True while a part is held at the cup."""
        ...

    def in_hand(self) -> bool:
        """True while the gripper holds the suction tool."""
        ...
