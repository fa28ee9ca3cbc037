"""The built-in ``freedrive`` capability: hand guiding and recording waypoints."""

from __future__ import annotations

from capabilities.freedrive.operations import capability

__all__ = ["capability"]
