"""The occupancy capability's settings: a module of their own, without numpy, so that the
capability's manifests load (``costar ops``, validation) without the point-cloud code.
"""

from __future__ import annotations

from capabilities.kit import Setting
from engine.types import Pose

__all__ = ["SETTINGS"]

SETTINGS = (
    Setting("table_z", float, None, "height (m) of the table top; without it the table plane "
            "is found in the frames of a fixed camera (the fullest horizontal slice)"),
    Setting("table_margin", float, 0.008, "points this close (m) to the table plane are the table"),
    Setting("robot_base", Pose, None, "world pose of the robot's base frame (default: from the arm)"),
    Setting("mask_inflate", float, 0.02, "how much (m) the robot's capsules grow when masking"),
    Setting("tool_radius", float, 0.07, "radius (m) of the tool's capsule (the parallel gripper)"),
    Setting("refresh_period", float, 0.1, "a frame older than this (s of cell time) is renewed"),
)  # fmt: skip  # a table: one setting a row
