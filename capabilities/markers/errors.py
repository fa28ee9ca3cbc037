"""The exception class of the markers capability."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["MarkerError"]


class MarkerError(CapabilityError):
    """Bad input to a marker function, or a marker problem that has no answer (no markers seen)."""
