"""Errors of the UR cell and the loopback UR controller."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["URError", "URConnectionLost", "EmulatorError"]


class URError(CapabilityError):
    """A UR controller refused or could not do what was asked."""


class URConnectionLost(URError):
    """The connection to the UR controller is gone."""


class EmulatorError(CapabilityError):
    """The loopback UR controller cannot start or was asked something it does not do."""
