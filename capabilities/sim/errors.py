"""The exception class of the simulated cell."""

from __future__ import annotations

from capabilities.robot.errors import RobotCellError

__all__ = ["SimError"]


class SimError(RobotCellError):
    """The simulated cell cannot do what was asked (not started, closed, bad scene)."""
