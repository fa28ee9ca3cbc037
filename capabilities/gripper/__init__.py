"""The built-in ``gripper`` capability: open and close the parallel gripper."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.gripper.operations import build_gripper_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_gripper_capability()
