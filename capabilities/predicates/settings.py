"""The predicates capability's settings and relations: a module without numpy, so that the
capability's manifests load (``costar ops``, validation) without its geometry.
"""

from __future__ import annotations

from capabilities.kit import Setting
from engine.types import Pose

__all__ = ["DIRECTIONS", "SETTINGS"]

SETTINGS = (
    Setting("robot_base", Pose, None, "world pose of the robot's base frame (default: from the arm)"),
    Setting("tool_size", tuple, (0.06, 0.12, 0.16), "full size (m) of the tool's box (the gripper)", 3),
    Setting("tool_center", tuple, (0.0, 0.0, -0.065), "the tool box's centre (m) in the TCP frame", 3),
    Setting("history", float, 10.0, "seconds of detections kept per object"),
)  # fmt: skip  # a table: one setting a row

# relation -> (axis, sign)
DIRECTIONS: dict[str, tuple[int, float]] = {
    "left_of": (1, 1.0),
    "right_of": (1, -1.0),
    "in_front_of": (0, 1.0),
    "behind": (0, -1.0),
    "up_from": (2, 1.0),
    "down_from": (2, -1.0),
}
