"""Where the cell's two RGB-D cameras sit by default: the shoulder stand and the wrist mount.

Poses are OpenCV camera frames (x right, y down, z forward). The cell file's defaults
(``cell_file``) and the simulated cameras (``capabilities.sim.cameras``) use them.
"""

from __future__ import annotations

import math

import numpy as np

from capabilities.geometry import matrix_to_pose
from capabilities.robot.errors import RobotCellError
from engine.types import Pose

__all__ = ["SHOULDER_EYE", "SHOULDER_TARGET", "WRIST_MOUNT", "look_at"]

# Where the shoulder camera's stand puts it: behind the robot base, off to its left (+y) so
# that the arm at home hides little of the table, aimed at the middle of the default table
# (centre x 0.55 m, top z 0).
SHOULDER_EYE = (-0.15, 0.45, 1.50)
SHOULDER_TARGET = (0.58, -0.02, 0.0)


def _wrist_mount(
    offset: float = 0.08, height: float = 0.02, tilt: float = math.radians(15)
) -> Pose:
    """The wrist camera in tool0 (z along the tool axis): beside the gripper on tool0's +x,
    image down toward the tool axis, tilted by ``tilt`` toward it so that the fingertips show
    at the bottom of the image and the optical axis meets the tool axis ~0.3 m out.
    """
    c, s = math.cos(tilt), math.sin(tilt)
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 deg about z
    rot = rot @ np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])  # -tilt about x
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rot, (offset, 0.0, height)
    return matrix_to_pose(m, project=False)


WRIST_MOUNT = _wrist_mount()


def look_at(
    eye: tuple[float, float, float],
    target: tuple[float, float, float],
    up: tuple[float, float, float] = (0.0, 0.0, 1.0),
) -> Pose:
    """The OpenCV camera pose at ``eye`` looking at ``target`` (image up toward ``up``).

    Raises:
        RobotCellError: the view direction is parallel to ``up``.
    """
    z = np.subtract(target, eye).astype(float)
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    if np.linalg.norm(x) < 1e-9:
        raise RobotCellError(f"look_at: the view direction {tuple(z)} is parallel to up {up}")
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, :3] = np.column_stack((x, np.cross(z, x), z))
    m[:3, 3] = eye
    return matrix_to_pose(m, project=False)
