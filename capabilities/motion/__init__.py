"""The built-in ``motion`` capability: move the arm to poses, waypoints and joints."""

from __future__ import annotations

from capabilities.motion.operations import capability

__all__ = ["capability"]
