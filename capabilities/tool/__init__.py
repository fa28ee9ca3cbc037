"""The built-in ``tool`` capability: the suction tool, its holster and its vacuum."""

from __future__ import annotations

from capabilities.tool.operations import capability

__all__ = ["capability"]
