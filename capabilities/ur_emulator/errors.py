"""The exception class of the loopback UR controller."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["EmulatorError"]


class EmulatorError(CapabilityError):
    """The loopback UR controller cannot start or was asked something it does not do."""
