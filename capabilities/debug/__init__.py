"""The built-in ``debug`` capability: always available, for tests, teaching and dry runs."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.debug.operations import build_debug_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_debug_capability()
