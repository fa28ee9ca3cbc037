"""The built-in ``timing`` capability: wait on the cell's clock, wait for a condition."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.timing.operations import build_timing_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_timing_capability()
