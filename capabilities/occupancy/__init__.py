"""The ``occupancy`` capability: is a sphere of space occupied? (paper IV-B).

Reads the depth point clouds of the cell's cameras; the table surface and the robot's own
body (capsules from its joint positions) never count as occupants.
"""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.occupancy.operations import build_capability

__all__ = ["capability"]


def capability() -> Capability:
    """Entry point of the ``costar.capabilities`` group."""
    return build_capability()
