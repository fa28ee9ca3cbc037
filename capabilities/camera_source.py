"""Where RGB-D frames come from: the camera-source interface every backend gives.

Capabilities (markers, perception, occupancy, collaboration) take a camera from the cell's
interfaces (``rgbd:<name>``, through ``capabilities.kit.camera``) and use only what
:class:`CameraSource` declares: ``capture()`` (blocks the calling worker thread, never the
engine's or the GUI's) returns an :class:`RGBDFrame`; ``extrinsics()`` is where the cell
believes the camera is, ``set_extrinsics()`` stores a calibration. Backends: the simulated
cell's cameras (``capabilities.sim.session.SimCameraDevice``), recorded frames
(``capabilities.recorded_frames``), frames served over a loopback socket (the UR emulator's
cameras, ``capabilities.stream_camera``) and an Intel RealSense (``capabilities.realsense``), so the
same perception runs on simulated, recorded and real frames. No Qt here: a camera panel can
consume the same interface.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from capabilities.geometry import pose_to_matrix
from engine.types import Pose

__all__ = ["CameraSource", "RGBDFrame", "SOURCE_KINDS", "stride_for"]

SOURCE_KINDS = ("sim", "recorded", "realsense", "stream")


@dataclass(frozen=True, eq=False)
class RGBDFrame:
    """One RGB-D image with everything needed to turn it into world points.

    Attributes:
        rgb: HxWx3 uint8.
        depth: HxW float32, metres along the optical axis; NaN where nothing was seen.
        K: 3x3 intrinsics.
        T_world_camera: the camera (OpenCV frame) in the world.
        stamp: time of the capture (s; simulation time when the caller gave it).
        camera: name of the camera.
    """

    rgb: np.ndarray
    depth: np.ndarray
    K: np.ndarray
    T_world_camera: Pose
    stamp: float
    camera: str = ""
    _cache: dict[int, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    def _valid(self, stride: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        depth = self.depth[::stride, ::stride]
        rows, cols = np.nonzero(np.isfinite(depth) & (depth > 0))
        return rows * stride, cols * stride, depth[rows, cols].astype(np.float64)

    def camera_points(self, stride: int = 1) -> np.ndarray:
        """Nx3 points in the camera frame (every ``stride``-th pixel with a depth)."""
        v, u, z = self._valid(stride)
        fx, fy, cx, cy = self.K[0, 0], self.K[1, 1], self.K[0, 2], self.K[1, 2]
        return np.column_stack(((u - cx) * z / fx, (v - cy) * z / fy, z))

    def point_cloud(self, stride: int = 1) -> np.ndarray:
        """Nx3 points in the world frame (every ``stride``-th pixel with a depth)."""
        if stride not in self._cache:
            t = pose_to_matrix(self.T_world_camera)
            self._cache[stride] = self.camera_points(stride) @ t[:3, :3].T + t[:3, 3]
        return self._cache[stride]

    def point_colors(self, stride: int = 1) -> np.ndarray:
        """Nx3 uint8 colours of the points of ``point_cloud(stride)``, in the same order."""
        v, u, _ = self._valid(stride)
        return self.rgb[v, u]

    def at_most(self, max_width: int | None) -> RGBDFrame:
        """This frame with every ``stride_for``-th pixel of each row and column, so that it
        is at most ``max_width`` wide (itself when it is already; None: itself). Its points
        are those of ``point_cloud(stride)``: K is scaled with the pixels.
        """
        stride = stride_for(int(self.depth.shape[1]), max_width)
        if stride == 1:
            return self
        scale = np.diag([1.0 / stride, 1.0 / stride, 1.0])
        return RGBDFrame(
            rgb=np.ascontiguousarray(self.rgb[::stride, ::stride]),
            depth=np.ascontiguousarray(self.depth[::stride, ::stride]),
            K=scale @ self.K,
            T_world_camera=self.T_world_camera,
            stamp=self.stamp,
            camera=self.camera,
        )


def stride_for(width: int, max_width: int | None) -> int:
    """The pixel stride that brings a ``width`` wide image to at most ``max_width`` columns."""
    return 1 if max_width is None or max_width >= width else -(-width // max(1, max_width))


@runtime_checkable
class CameraSource(Protocol):
    """An RGB-D camera of a cell.

    Attributes:
        name: the camera's name in the cell ("shoulder", "wrist").
        on_wrist: mounted on the flange, moving with the arm.
    """

    name: str
    on_wrist: bool

    @property
    def intrinsics(self) -> np.ndarray:
        """The 3x3 camera matrix K of the frames it gives."""
        ...

    def capture(self, max_width: int | None = None) -> RGBDFrame:
        """The next frame; blocks the calling (worker) thread.

        Args:
            max_width: a consumer that uses only so many columns (occupancy) asks for a
                frame at most this wide: the same view with every n-th pixel (see
                :meth:`RGBDFrame.at_most`). A simulated camera renders only those pixels, at
                a fraction of a full frame's cost.
        """
        ...

    def extrinsics(self) -> Pose:
        """The camera (OpenCV frame) in the world, as the cell believes it is now."""
        ...

    def set_extrinsics(self, pose: Pose) -> None:
        """Store a calibration: the world pose (fixed camera) or the flange pose (wrist)."""
        ...
