"""Errors of the collaboration capability."""

from __future__ import annotations

__all__ = ["CollaborationError"]


class CollaborationError(Exception):
    """Something about operator interaction or the simulated worker is wrong."""
