"""How much of the table the robot arm hides from a fixed camera.

A look that finds nothing because the arm stands between the camera and the table must say
so, or a plan that looks again and again loops for ever (issue 26).

The arm's geometry comes from the cell's arm interface: its joint positions, read right
after the frame, placed by the UR5 body model (:class:`capabilities.robot_body.RobotBody`,
forward kinematics, one capsule per link and the tool). The frame's depth gives a world
point per pixel; a pixel whose point lies on the arm's body and whose ray, continued, meets
the table plane inside the work area is table the arm hides. The table plane is the median
height of the other points over the work area. The share of the work area's pixels hidden
that way is :attr:`ArmCover.share`.

numpy loads with this module: the operations import it inside the look that uses it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from capabilities.geometry import pose_to_matrix
from capabilities.robot_body import (
    Capsule,
    RobotBody,
    RobotBodyError,
    matrix_pose,
    pose_matrix,
    robot_base_from_arm,
)

__all__ = ["HIDDEN_SHARE", "WORK_AREA", "ArmCover", "ArmView", "Glance"]

# A look that finds nothing while the arm hides this share of the work area's table blames
# the arm (the arm at "step out of view" hides none; over the table, a third or more).
HIDDEN_SHARE = 0.1
# The table's work area (world x, y min and max, m): perception's default workspace.
WORK_AREA = ((0.1, -0.65), (1.0, 0.65))
_INFLATE = 0.02  # the body's capsules grow this much (m): depth noise at the arm's edges
_MAX_WIDTH = 160  # pixels across the frame that are checked (every n-th column and row)
_STILL = ("base_link", "shoulder_link")  # they only turn where they stand, off the table
_ABOVE_TABLE = 0.5  # points this high (m) above the table still count as over the work area


@dataclass(frozen=True)
class ArmCover:
    """How much of the work area's table the arm hides from one camera in one frame."""

    camera: str
    share: float  # of the work area's pixels in the frame, 0..1

    @property
    def hides(self) -> bool:
        return self.share >= HIDDEN_SHARE

    def sentence(self) -> str:
        return (
            f"the arm hides the table from the {self.camera} camera "
            f"({100 * self.share:.0f}% of the work area)"
        )


class ArmView:
    """Measures the arm's cover of the table in the frames of a cell's fixed cameras.

    Args:
        arm: the cell's arm interface (``joint_positions()``; ``tcp_offset()``, and
            ``robot_base()`` or forward kinematics when it has them).
        work_area: ((x_min, y_min), (x_max, y_max)) of the table, world frame (m).
    """

    def __init__(self, arm: Any, work_area: tuple[Sequence[float], Sequence[float]] = WORK_AREA):
        self._arm = arm
        self.low = np.asarray(work_area[0][:2], dtype=float)
        self.high = np.asarray(work_area[1][:2], dtype=float)
        self._body: RobotBody | None = None

    def glance(self, camera: Any, frame: Any) -> Glance | None:
        """The arm as it stands now (just after ``frame``), to judge the frame by later; None
        when that cannot be told (a camera on the wrist, a frame without depth, an arm
        without a body model).
        """
        if getattr(camera, "on_wrist", False) or getattr(frame, "depth", None) is None:
            return None
        if not callable(getattr(frame, "point_cloud", None)):
            return None
        arm = self._arm
        try:
            if self._body is None:
                self._body = RobotBody(robot_base_from_arm(arm))
            q = tuple(float(v) for v in arm.joint_positions())
            if callable(getattr(arm, "tcp_offset", None)):
                tcp = arm.tcp_offset()
            else:
                flange = pose_matrix(self._body.flange_pose(q))
                tcp = matrix_pose(np.linalg.inv(flange) @ pose_matrix(arm.tcp_pose()))
            capsules = self._body.capsules(q, tcp, _INFLATE)
        except (RobotBodyError, AttributeError, TypeError, ValueError):
            return None
        moving = [capsule for capsule in capsules if capsule.link not in _STILL]
        return Glance(self, str(camera.name), frame, moving)


class Glance:
    """One frame of a fixed camera and the capsules of the arm's moving links when it was
    taken; the cover is measured only when asked for (a look that found nothing).
    """

    def __init__(self, view: ArmView, camera: str, frame: Any, arm: list[Capsule]) -> None:
        self._view = view
        self.camera = camera
        self._frame = frame
        self._arm = arm
        self._cover: ArmCover | None = None

    def cover(self) -> ArmCover:
        """The share of the work area's table the arm hides in this frame."""
        if self._cover is None:
            width = int(self._frame.depth.shape[1])
            stride = max(1, -(-width // _MAX_WIDTH))
            points = np.asarray(self._frame.point_cloud(stride), dtype=float)
            self._cover = ArmCover(self.camera, self._share(points))
            self._frame = None  # the frame is not needed any more
        return self._cover

    def hides(self) -> ArmCover | None:
        """The cover when the arm hides the table (:attr:`ArmCover.hides`), else None."""
        cover = self.cover()
        return cover if cover.hides else None

    def _share(self, points: np.ndarray) -> float:
        if len(points) == 0:
            return 0.0
        low, high = self._view.low, self._view.high
        on_arm = np.zeros(len(points), dtype=bool)
        for capsule in self._arm:
            on_arm |= capsule.distance(points) <= 0.0
        over = np.all((points[:, :2] >= low) & (points[:, :2] <= high), axis=1)
        rest = points[over & ~on_arm]
        if len(rest) == 0:
            return 1.0 if on_arm.any() else 0.0
        table_z = float(np.median(rest[:, 2]))
        visible = int(np.count_nonzero(rest[:, 2] <= table_z + _ABOVE_TABLE))
        centre = pose_to_matrix(self._frame.T_world_camera)[:3, 3]
        arm_points = points[on_arm]
        rise = arm_points[:, 2] - centre[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (table_z - centre[2]) / rise
        behind = np.isfinite(t) & (t > 1.0)  # the table lies beyond the arm along the ray
        hits = centre + t[behind, None] * (arm_points[behind] - centre)
        inside = np.all((hits[:, :2] >= low) & (hits[:, :2] <= high), axis=1)
        hidden = int(np.count_nonzero(inside))
        return hidden / (hidden + visible) if hidden + visible else 0.0
