"""Seeing a handoff: an object placed in a region, found by its ArUco markers in camera images.

:func:`find_object` looks for one object's markers in a frame. When a region is given it
searches only the part of the image where the region (grown by the object's size) can
appear: the crop is an exact change of the principal point, so poses are unchanged, and a
crop of a fifth of the image is detected about five times faster, which is most of the
latency of a handoff. :class:`HandoffJob` polls a camera at a fixed interval of the cell's
clock on its own thread until the object is seen inside the region and still.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from capabilities.markers.backend import CameraDevice, FrameLike
from capabilities.markers.depth import refine_with_depth
from capabilities.markers.detection import (
    detect_markers,
    marker_pose_world,
    object_pose_from_marker,
)
from capabilities.world_model import Detection, WorldModel
from engine.error_types import ErrorType
from engine.operations import Job
from engine.types import Pose, Region

__all__ = [
    "HandoffJob",
    "HandoffSettings",
    "ObjectMarkers",
    "find_object",
    "in_region",
    "object_markers",
    "region_crop",
]

# Markers seen this badly are ignored (an almost face-on marker whose tilt may be mirrored).
MIN_CONFIDENCE = 0.05
# Pixels added around the projected region: marker corners near the crop edge get lost.
CROP_MARGIN_PX = 12
# The poll thread checks the cell's clock this often (wall seconds) while it waits.
WAIT_SLICE_S = 0.002


@dataclass(frozen=True)
class ObjectMarkers:
    """An object model's markers: name, id -> (side in m, pose in the object frame), reach
    (m from the object frame's origin to its farthest point, to size the crop).
    """

    name: str
    markers: Mapping[int, tuple[float, Pose]]
    reach: float


def in_region(pose: Pose, region: Region) -> bool:
    """True when the pose's position is inside the region's sphere."""
    return math.dist(pose.position, region.center) <= region.radius


def region_crop(frame: FrameLike, region: Region, grow: float) -> tuple[int, int, int, int] | None:
    """(x0, y0, x1, y1) of the image part where a sphere of ``region.radius + grow`` around
    the region's centre can appear; None when it may cover the whole image.
    """
    height, width = frame.rgb.shape[:2]
    centre = frame.T_world_camera.inverse().compose(Pose(region.center)).position
    radius = region.radius + grow
    if centre[2] <= radius * 1.05:  # the sphere reaches the camera: no useful bound
        return None
    k = frame.K
    u = k[0, 0] * centre[0] / centre[2] + k[0, 2]
    v = k[1, 1] * centre[1] / centre[2] + k[1, 2]
    # A sphere at depth z seen by a pinhole spans at most f * R / sqrt(z^2 - R^2) pixels from
    # its centre's image (a little more off-axis: the margin covers it).
    spread = radius / math.sqrt(centre[2] ** 2 - radius**2)
    half = max(k[0, 0], k[1, 1]) * spread + CROP_MARGIN_PX
    x0, y0 = max(0, int(u - half)), max(0, int(v - half))
    x1, y1 = min(width, math.ceil(u + half) + 1), min(height, math.ceil(v + half) + 1)
    if x1 - x0 < 8 or y1 - y0 < 8:
        return None
    return x0, y0, x1, y1


def find_object(
    frame: FrameLike, target: ObjectMarkers, source: str, region: Region | None = None
) -> Detection | None:
    """The object's pose from its most confident marker in ``frame``, or None if not seen.

    Args:
        frame: an RGB-D frame with its believed camera pose.
        target: the object's markers.
        source: the detection's source name (e.g. "collaboration:shoulder").
        region: search only where this region (grown by the object's reach) appears.
    """
    box = region_crop(frame, region, target.reach) if region is not None else None
    rgb, depth, k = frame.rgb, frame.depth, np.asarray(frame.K, dtype=np.float64)
    if box is not None:
        x0, y0, x1, y1 = box
        rgb = np.ascontiguousarray(rgb[y0:y1, x0:x1])
        depth = depth[y0:y1, x0:x1] if depth is not None else None
        k = k.copy()
        k[0, 2] -= x0
        k[1, 2] -= y0
    sizes = {marker_id: size for marker_id, (size, _) in target.markers.items()}
    best: Detection | None = None
    for seen in detect_markers(rgb, k, sizes):
        if depth is not None:
            seen = refine_with_depth(seen, depth, k)
        if seen.confidence < MIN_CONFIDENCE:
            continue
        pose = object_pose_from_marker(
            marker_pose_world(seen, frame.T_world_camera), target.markers[seen.marker_id][1]
        )
        if best is None or seen.confidence > best.confidence:
            best = Detection(
                target.name, pose, seen.confidence, frame.stamp, source, f"marker {seen.marker_id}"
            )
    return best


@dataclass(frozen=True)
class HandoffSettings:
    """How a handoff is watched (times on the cell's clock, in seconds).

    Attributes:
        interval: time between frames.
        settle: how long the object must stay put inside the region (0: the first sighting
            inside counts).
        still_tolerance: how far (m) it may move meanwhile and still count as put down.
        timeout: give up after this long (0: never).
    """

    interval: float = 0.1
    settle: float = 0.0
    still_tolerance: float = 0.01
    timeout: float = 0.0


class HandoffJob(Job):
    """Watches a camera on its own thread until the object lies still inside the region.

    A dedicated thread, not the cell's worker pool: a handoff may be awaited for minutes and
    would hold one of the pool's few threads all that time.

    On success the output is ``pose`` (the object's detected pose); ``decided`` holds the
    frame's cell time. Every frame's sighting replaces what the source said before in the
    world model (source ``collaboration:<camera>``).
    """

    def __init__(
        self,
        camera: CameraDevice,
        target: ObjectMarkers,
        region: Region,
        world: WorldModel,
        clock: Callable[[], float],
        settings: HandoffSettings,
        log: Callable[[str], None] = lambda _text: None,
    ) -> None:
        self._stop = threading.Event()
        super().__init__(on_cancel=self._stop.set)
        self._camera, self._target, self._region = camera, target, region
        self._world, self._clock, self._settings, self._log = world, clock, settings, log
        self.source = f"collaboration:{camera.name}"
        self.frames = 0
        self.decided: float | None = None
        self._thread = threading.Thread(target=self._run, name="costar-handoff", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            self._watch()
        except Exception as exc:  # a camera or perception failure fails the node, not the engine
            self.fail(f"watching for {self._target.name}: {type(exc).__name__}: {exc}")

    def _watch(self) -> None:
        settings = self._settings
        start = self._clock()
        since: Detection | None = None  # first sighting of the current still stretch
        next_frame = start
        while not self._stop.is_set():
            self._wait_until(next_frame)
            if self._stop.is_set():
                return
            next_frame = self._clock() + settings.interval
            frame = self._camera.capture()
            self.frames += 1
            seen = find_object(frame, self._target, self.source, self._region)
            self._world.replace(self.source, [seen] if seen is not None else [])
            since = self._still_since(since, seen)
            if (
                seen is not None
                and since is not None
                and seen.stamp - since.stamp >= settings.settle
            ):
                self._log(
                    f"{self._target.name} handed over at {_xyz(seen.pose)} "
                    f"(frame at {seen.stamp:.2f} s)"
                )
                self.decided = seen.stamp
                self.succeed(outputs={"pose": seen.pose})
                return
            if settings.timeout > 0 and self._clock() - start >= settings.timeout:
                self.fail(
                    f"timed out: no {self._target.name} put down in the region "
                    f"within {settings.timeout:g} s",
                    ErrorType.TIMEOUT,
                )
                return

    def _still_since(self, since: Detection | None, seen: Detection | None) -> Detection | None:
        if seen is None or not in_region(seen.pose, self._region):
            return None
        if since is None:
            return seen
        moved = math.dist(seen.pose.position, since.pose.position)
        return since if moved <= self._settings.still_tolerance else seen

    def _wait_until(self, cell_time: float) -> None:
        # The cell's clock may run faster or slower than the wall clock: watch it in slices.
        while self._clock() < cell_time and not self._stop.wait(WAIT_SLICE_S):
            pass

    @property
    def watching(self) -> bool:
        """True while the poll thread runs."""
        return self._thread.is_alive()

    def join(self, timeout: float | None = None) -> None:
        """Wait for the poll thread to end (tests; after cancel or finish)."""
        self._thread.join(timeout)


def _xyz(pose: Pose) -> str:
    return "(" + ", ".join(f"{v * 1000:.0f}" for v in pose.position) + ") mm"


def object_markers(spec: Any) -> ObjectMarkers:
    """ObjectMarkers of an object library model (``ObjectModelSpec``)."""
    markers = {m.marker_id: (m.size, m.pose) for m in spec.markers}
    dims = spec.dimensions
    reach = math.hypot(dims[0] / 2, dims[1] / 2, dims[2])
    return ObjectMarkers(spec.name, markers, reach)
