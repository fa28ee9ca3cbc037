"""The built-in ``timing`` capability: wait until a condition holds."""

from __future__ import annotations

from capabilities.timing.operations import capability

__all__ = ["capability"]
