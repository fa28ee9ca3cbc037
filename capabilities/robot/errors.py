"""The exception class of what every cell shares."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["CellError"]


class CellError(CapabilityError, RuntimeError):
    """A cell cannot be described or built: a cell file that is off, a missing robot model."""
