"""An Intel RealSense RGB-D camera as a camera source (the optional ``realsense`` extra).

pyrealsense2 is imported when a camera is opened, never at start-up: a cell without a RealSense
needs none. Depth is aligned to the colour image, so one K serves both, and converted to metres
(0 reads as NaN: no reading), as every camera source gives it.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np

from capabilities.camera_source import RGBDFrame
from capabilities.errors import CapabilityError
from engine.types import Pose

__all__ = ["RealSenseCamera", "RealSenseError"]

_TIMEOUT_MS = 5000


class RealSenseError(CapabilityError):
    """The RealSense camera (or its library) is not there or stopped answering."""


class RealSenseCamera:
    """One RealSense on a stand, streaming colour and depth.

    Args:
        name: the camera's name in the cell.
        serial: the device's serial number ("" for the only one connected).
        size: (width, height) of both streams.
        fps: frames per second.
        extrinsics: the camera (OpenCV frame) in the world, until a calibration replaces it.

    Raises:
        RealSenseError: pyrealsense2 is not installed or no such camera answers.
    """

    def __init__(
        self,
        name: str,
        serial: str = "",
        size: tuple[int, int] = (640, 480),
        fps: int = 30,
        extrinsics: Pose | None = None,
    ) -> None:
        try:
            import pyrealsense2 as rs
        except ImportError as exc:
            raise RealSenseError(
                f"camera {name}: a RealSense needs pyrealsense2 "
                "(pip install 'costar-instructor[realsense]')"
            ) from exc
        self.name = name
        self.on_wrist = False  # a fixed camera: a wrist one needs the arm's pose per frame
        self._pose = extrinsics or Pose()
        self._lock = threading.Lock()
        self._rs: Any = rs
        self._pipeline = rs.pipeline()
        config = rs.config()
        if serial:
            config.enable_device(serial)
        width, height = size
        config.enable_stream(rs.stream.color, width, height, rs.format.rgb8, fps)
        config.enable_stream(rs.stream.depth, width, height, rs.format.z16, fps)
        try:
            profile = self._pipeline.start(config)
        except RuntimeError as exc:
            raise RealSenseError(
                f"camera {name}: no RealSense {serial or ''} answers: {exc}"
            ) from exc
        self._align = rs.align(rs.stream.color)
        self._scale = float(profile.get_device().first_depth_sensor().get_depth_scale())
        color = profile.get_stream(rs.stream.color).as_video_stream_profile()
        i = color.get_intrinsics()
        self._k = np.array([[i.fx, 0.0, i.ppx], [0.0, i.fy, i.ppy], [0.0, 0.0, 1.0]])

    @property
    def intrinsics(self) -> np.ndarray:
        return self._k.copy()

    def extrinsics(self) -> Pose:
        return self._pose

    def set_extrinsics(self, pose: Pose) -> None:
        self._pose = pose

    def capture(self, max_width: int | None = None) -> RGBDFrame:
        with self._lock:
            try:
                frames = self._align.process(self._pipeline.wait_for_frames(_TIMEOUT_MS))
            except RuntimeError as exc:
                raise RealSenseError(f"camera {self.name}: no frame: {exc}") from exc
            color, depth = frames.get_color_frame(), frames.get_depth_frame()
            if not color or not depth:
                raise RealSenseError(f"camera {self.name}: a frame without colour or depth")
            counts = np.asanyarray(depth.get_data())
            metres = counts.astype(np.float32) * np.float32(self._scale)
            metres[counts == 0] = np.nan
            return RGBDFrame(
                rgb=np.asanyarray(color.get_data()).copy(),
                depth=metres,
                K=self._k.copy(),
                T_world_camera=self._pose,
                stamp=time.monotonic(),
                camera=self.name,
            ).at_most(max_width)

    def close(self) -> None:
        """Stop streaming."""
        self._pipeline.stop()
