"""The exception class of the simulated cell."""

from __future__ import annotations

__all__ = ["SimError"]


class SimError(RuntimeError):
    """The simulated cell cannot do what was asked (not started, closed, bad config)."""
