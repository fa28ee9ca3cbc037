"""The exception class of the simulated cell."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["SimError"]


class SimError(CapabilityError, RuntimeError):
    """The simulated cell cannot do what was asked (not started, closed, bad config)."""
