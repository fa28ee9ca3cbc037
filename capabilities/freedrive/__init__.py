"""The built-in ``freedrive`` capability: hand guiding and recording waypoints."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.freedrive.operations import build_freedrive_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_freedrive_capability()
