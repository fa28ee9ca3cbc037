"""The ``occupancy`` capability: is a sphere of space occupied? (paper IV-B).

Reads the depth point clouds of the cell's cameras; the table surface and the robot's own
body (capsules from its joint positions) never count as occupants.
"""

from __future__ import annotations

from capabilities.occupancy.operations import capability

__all__ = ["capability"]
