"""Errors of the perception capability."""

from __future__ import annotations

from capabilities.errors import CapabilityError

__all__ = ["PerceptionError"]


class PerceptionError(CapabilityError):
    """Recognition could not run (no table in view, a model mesh that cannot be read)."""
