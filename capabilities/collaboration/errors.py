"""Errors of the collaboration capability."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["CollaborationError"]


class CollaborationError(CapabilityError):
    """Something about operator interaction or the simulated worker is wrong."""
