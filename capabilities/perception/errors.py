"""Errors of the perception capability."""

from __future__ import annotations

__all__ = ["PerceptionError"]


class PerceptionError(Exception):
    """Recognition could not run (no table in view, a model mesh that cannot be read)."""
