"""The built-in ``gripper`` capability: open and close the parallel gripper."""

from __future__ import annotations

from capabilities.gripper.operations import capability

__all__ = ["capability"]
