"""What the freedrive capability needs from a cell: hand guiding and the arm's state.

The simulated cell's ``SimRobot`` implements it as it is; the ur_rtde backend maps it to
freedriveMode/endFreedriveMode (PolyScope 5.10 and later) or teachMode/endTeachMode.
``set_freedrive`` may wait for the controller for a few milliseconds, so the operations call
it off the engine thread.
"""

from __future__ import annotations

from typing import Protocol

from engine.types import Pose

__all__ = ["FREEDRIVE", "FreedriveBackend"]

FREEDRIVE = "freedrive"


class FreedriveBackend(Protocol):
    """Hand guiding of the arm, and where the hand left it."""

    def set_freedrive(self, on: bool) -> None:
        """Start or stop hand guiding (stopping holds the arm where it is)."""
        ...

    def freedrive_active(self) -> bool:
        """True while hand guiding is on."""
        ...

    def tcp_pose(self) -> Pose:
        """World pose of the current tool's TCP."""
        ...

    def joint_positions(self) -> tuple[float, ...]:
        """Measured joint positions (rad), base to wrist."""
        ...
