"""What the occupancy operations of one cell share: camera feeds, the table, the robot body.

One :class:`OccupancyState` per cell, made by the capability's ``setup`` hook: every
occupancy node of a plan reads the same latest frame of a camera, so two conditions on one
camera do not render twice. Its settings (:data:`SETTINGS`) come from the cell file's
``capabilities.occupancy`` block.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from capabilities import kit
from capabilities.base import CapabilityEnv
from capabilities.occupancy.feed import CameraFeed, Capture
from capabilities.occupancy.region import RegionReading, estimate_table_z, read_region
from capabilities.occupancy.settings import SETTINGS
from capabilities.robot_body import (
    RobotBody,
    RobotBodyError,
    matrix_pose,
    pose_matrix,
    robot_base_from_arm,
)
from engine.operations import OperationFailed
from engine.types import Pose, Region

__all__ = ["SETTINGS", "OccupancyState", "setup"]


class OccupancyState:
    """The shared occupancy machinery of one cell."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._env = env
        settings = env.settings  # checked against SETTINGS: typed, defaults filled in
        self.workers = env.interface("workers")
        self.arm = env.cell.interfaces().get("arm")
        self.table_z_setting: float | None = settings["table_z"]
        self.table_margin: float = settings["table_margin"]
        self.mask_inflate: float = settings["mask_inflate"]
        self.tool_radius: float = settings["tool_radius"]
        self.refresh_period: float = settings["refresh_period"]
        self._base_setting: Pose | None = settings["robot_base"]
        self._lock = threading.Lock()
        self._feeds: dict[str, CameraFeed] = {}
        self._body: RobotBody | None = None
        self._table_z: float | None = None
        self._table_of: tuple[Capture, float | None] | None = None

    def clock(self) -> float:
        return self._env.cell.clock()

    def feed(self, camera: str) -> CameraFeed:
        """The feed of a camera ("shoulder" or "wrist"); raises OperationFailed if missing."""
        with self._lock:
            if camera not in self._feeds:
                device = kit.camera(self._env, camera)
                reader = self._read_robot if self.arm is not None else None
                self._feeds[camera] = CameraFeed(device, self.workers, reader)
            return self._feeds[camera]

    def body(self) -> RobotBody:
        """The robot body model (its base found once)."""
        with self._lock:
            if self._body is None:
                try:
                    base = robot_base_from_arm(self.arm, self._base_setting)
                except RobotBodyError as exc:
                    raise OperationFailed(str(exc)) from exc
                self._body = RobotBody(base, tool_radius=self.tool_radius)
            return self._body

    def _read_robot(self) -> tuple[tuple[float, ...], Pose | None]:
        arm: Any = self.arm
        q = tuple(float(v) for v in arm.joint_positions())
        if callable(getattr(arm, "tcp_offset", None)):
            return q, arm.tcp_offset()
        flange = pose_matrix(self.body().flange_pose(q))
        return q, matrix_pose(np.linalg.inv(flange) @ pose_matrix(arm.tcp_pose()))

    def table_z(self, capture: Capture) -> float | None:
        """The table height for a capture: configured, else found in fixed-camera frames."""
        if self.table_z_setting is not None:
            return self.table_z_setting
        with self._lock:
            if self._table_of is not None and self._table_of[0] is capture:
                return self._table_of[1]
            cached = self._table_z
        found = estimate_table_z(capture.points)
        with self._lock:
            if not capture.on_wrist and found is not None:
                # A fixed camera sees the whole table; its plane is kept for wrist frames,
                # which may look at a large box top instead.
                self._table_z = cached = found
            value = cached if cached is not None else found
            self._table_of = (capture, value)
        return value

    def read(self, capture: Capture, region: Region, mask_robot: bool) -> RegionReading:
        """Count the occupant points of ``region`` in ``capture``."""
        mask = None
        if mask_robot:
            if not capture.joints:
                raise OperationFailed("cannot mask the robot: the cell has no arm")
            body = self.body()
            inflate = self.mask_inflate

            def mask(points: np.ndarray) -> np.ndarray:
                # Joints read before and after the frame: the arm was between the two.
                on = np.zeros(len(points), dtype=bool)
                for q in capture.joints:
                    on |= body.contains(points, q, capture.tcp_offset, inflate)
                return on

        return read_region(capture.points, region, self.table_z(capture), self.table_margin, mask)


def setup(env: CapabilityEnv) -> OccupancyState:
    """The capability's per-cell hook: the state all occupancy operations of a cell share."""
    return OccupancyState(env)
