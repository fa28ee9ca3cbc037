"""What the markers capability needs from a cell."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Protocol

from engine.types import Pose

if TYPE_CHECKING:  # numpy only for the annotations: manifests load without it
    import numpy as np

__all__ = ["CameraDevice", "FrameLike", "MarkerLayout"]


class FrameLike(Protocol):
    """A camera frame: colour and depth images, intrinsics, the camera's pose, its time."""

    rgb: np.ndarray
    depth: np.ndarray | None
    K: np.ndarray
    T_world_camera: Pose
    stamp: float


class CameraDevice(Protocol):
    """An RGB-D camera: ``capture`` blocks the caller (call it from a worker thread)."""

    name: str
    on_wrist: bool

    def capture(self) -> FrameLike: ...

    def extrinsics(self) -> Pose: ...

    def set_extrinsics(self, pose: Pose) -> None: ...


class MarkerLayout(Protocol):
    """The cell's marker configuration (``scene_layout``): sizes and table markers."""

    def __getitem__(self, key: str) -> Mapping[int, Any]: ...
