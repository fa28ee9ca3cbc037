"""The built-in ``tool`` capability: the suction tool, its holster and its vacuum."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.tool.operations import build_tool_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_tool_capability()
