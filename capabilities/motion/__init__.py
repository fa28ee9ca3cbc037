"""The built-in ``motion`` capability: move the arm to poses, waypoints and joints."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.motion.operations import build_motion_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_motion_capability()
