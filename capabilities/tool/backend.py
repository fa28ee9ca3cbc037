"""What the tool capability needs from a cell: the suction tool (plus the arm and gripper).

The suction tool rests in a holster; the gripper takes it by its handle. While it is held,
the cell's TCP is the suction cup's tip. The simulated cell's ``SimSuctionTool`` implements
:class:`SuctionBackend` as it is; a real cell switches the vacuum through a digital output
and reads the vacuum sensor from an input. The arm and gripper interfaces are the motion and
gripper capabilities' backends; :class:`SuctionBackend` extends what a grasp reads of the
tool (``capabilities.gripper.backend.HeldSuctionTool``).
"""

from __future__ import annotations

from typing import Protocol

from capabilities.gripper.backend import HeldSuctionTool
from capabilities.jobs import CommandHandleLike
from engine.types import Pose

__all__ = ["SuctionBackend"]


class SuctionBackend(HeldSuctionTool, Protocol):
    """The suction tool: vacuum, vacuum sensor, and where its holster is."""

    def suction_off(self) -> CommandHandleLike:
        """Switch the vacuum off, releasing the part."""
        ...

    def vacuum_on(self) -> bool:
        """True while the vacuum is switched on."""
        ...

    def handle_grasp_pose(self) -> Pose:
        """World gripper TCP pose that grasps the handle of the holstered tool."""
        ...

    def holstered_tip_pose(self) -> Pose:
        """World TCP pose (the cup tip) that puts the held tool back in its holster."""
        ...
