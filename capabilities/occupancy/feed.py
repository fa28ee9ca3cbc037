"""The latest point cloud of each camera, refreshed on a worker thread.

Conditions must answer within a tick, and a camera frame takes tens of milliseconds: so a
:class:`CameraFeed` keeps the latest capture of its camera (world points, its stamp, and the
robot's joints around it) and starts a new capture on the cell's worker pool when asked.
Whoever waits for a capture subscribes a callback (the engine's wake) that runs when one
lands.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from capabilities.camera_source import stride_for
from engine.types import Pose

__all__ = ["Capture", "CameraFeed", "RobotReader"]

RobotReader = Callable[[], tuple[tuple[float, ...], Pose | None]]
"""Reads (joint positions, TCP offset in the flange frame) of the arm now."""


@dataclass(frozen=True, eq=False)
class Capture:
    """One camera frame as occupancy uses it.

    Attributes:
        points: Nx3 world points (m).
        stamp: the cell's clock when the frame was taken (s).
        camera: the camera's name.
        on_wrist: True for a camera that moves with the arm.
        joints: the arm's joints read just before and just after the frame (empty: no arm).
        tcp_offset: the tool's TCP in the flange frame when the frame was taken.
    """

    points: np.ndarray
    stamp: float
    camera: str
    on_wrist: bool
    joints: tuple[tuple[float, ...], ...] = ()
    tcp_offset: Pose | None = None


class CameraFeed:
    """One camera's latest capture, and at most one capture in flight.

    Args:
        camera: an RGB-D camera interface (``capture()`` blocks; ``name``, ``on_wrist``).
        workers: the cell's worker pool (``submit(fn, describe)``).
        robot: reads the arm's joints and TCP offset (None: the cell has no arm).
        max_width: point clouds are subsampled to at most this many columns (speed).
    """

    def __init__(
        self, camera: Any, workers: Any, robot: RobotReader | None, max_width: int = 320
    ) -> None:
        self._camera = camera
        self._workers = workers
        self._robot = robot
        self._max_width = max_width
        self._lock = threading.Lock()
        self._latest: Capture | None = None
        self._error = ""
        self._errors = 0
        self._busy = False
        self._listeners: list[Callable[[], None]] = []
        self.name = str(getattr(camera, "name", "camera"))

    def latest(self) -> Capture | None:
        """The newest capture, or None before the first one."""
        with self._lock:
            return self._latest

    def error(self) -> str:
        """Why the last capture failed ("" when it did not)."""
        with self._lock:
            return self._error

    def error_count(self) -> int:
        """How many captures have failed so far."""
        with self._lock:
            return self._errors

    def refresh(self) -> None:
        """Start a capture on a worker unless one is already running."""
        with self._lock:
            if self._busy:
                return
            self._busy = True
        try:
            self._workers.submit(self._capture_once, f"occupancy: {self.name} camera frame")
        except Exception as exc:  # a shut-down pool: report it as the capture's failure
            self._done(None, str(exc))

    def subscribe(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` (from a worker thread) whenever a capture lands or fails."""
        with self._lock:
            self._listeners.append(callback)

    def unsubscribe(self, callback: Callable[[], None]) -> None:
        with self._lock:
            if callback in self._listeners:
                self._listeners.remove(callback)

    def _capture_once(self) -> dict[str, Any]:
        try:
            capture = self._take()
        except Exception as exc:  # a camera or arm failure fails the waiting nodes, not the pool
            self._done(None, f"{type(exc).__name__}: {exc}")
        else:
            self._done(capture, "")
        return {}

    def _take(self) -> Capture:
        before = self._robot() if self._robot is not None else None
        # A frame only as wide as the clouds are (a simulated camera renders just that).
        frame = self._camera.capture(max_width=self._max_width)
        after = self._robot() if self._robot is not None else None
        stride = stride_for(int(frame.depth.shape[1]), self._max_width)
        joints = tuple(r[0] for r in (before, after) if r is not None)
        return Capture(
            points=np.asarray(frame.point_cloud(stride), dtype=float),
            stamp=float(frame.stamp),
            camera=self.name,
            on_wrist=bool(getattr(self._camera, "on_wrist", False)),
            joints=joints,
            tcp_offset=after[1] if after is not None else None,
        )

    def _done(self, capture: Capture | None, error: str) -> None:
        with self._lock:
            if capture is not None:
                self._latest = capture
            self._error = error
            self._errors += bool(error)
            self._busy = False
            listeners = list(self._listeners)
        for callback in listeners:
            callback()
