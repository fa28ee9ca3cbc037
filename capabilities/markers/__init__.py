"""The ``markers`` capability: ArUco markers in camera images (paper IV-B's AR tracking).

Detects markers in a camera's image (OpenCV), gives marker and object poses in the world
frame, and calibrates a camera's extrinsics from markers of known pose.
"""

from __future__ import annotations

from capabilities.markers.errors import MarkerError
from capabilities.markers.operations import capability

__all__ = ["MarkerError", "capability"]
