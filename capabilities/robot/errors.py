"""The exception class of what every cell shares."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["RobotCellError"]


class RobotCellError(CapabilityError, RuntimeError):
    """What every cell shares cannot do what was asked: a cell file that is off, a missing
    robot model, a camera that cannot look where asked (``capabilities.cells.CellError`` is
    the other one: a cell that could not be opened).
    """
