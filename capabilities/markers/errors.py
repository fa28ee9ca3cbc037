"""The exception class of the markers capability."""

from __future__ import annotations

__all__ = ["MarkerError"]


class MarkerError(Exception):
    """Bad input to a marker function, or a marker problem that has no answer (no markers seen)."""
