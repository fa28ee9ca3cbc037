"""Seeing a handoff: an object placed in a region, found by its ArUco markers in camera images.

:func:`find_object` looks for one object's markers in a frame. When a region is given it
searches only the part of the image where the region (grown by the object's size) can
appear: the crop is an exact change of the principal point, so poses are unchanged, and a
crop of a fifth of the image is detected about five times faster, which is most of the
latency of a handoff. :class:`HandoffJob` looks at a camera at a fixed interval of the cell's
clock until the object is seen inside the region and still.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from capabilities.jobs import WorkerPool
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
from engine.status import RUNNING, SUCCESS, Status
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
    """Watches a camera until the object lies still inside the region.

    Polled by the engine at every tick: once a frame is due (every ``interval`` of the
    cell's clock) it is taken and searched on the cell's worker pool, one at a time, and
    what it shows is weighed here, on the engine's thread. A handoff may be awaited for
    minutes without holding a pool thread between frames, and a simulated cell in lockstep
    sees every frame at the same tick however busy the machine is.

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
        workers: WorkerPool,
        log: Callable[[str], None] = lambda _text: None,
    ) -> None:
        super().__init__(on_cancel=self._cancel_frame)
        self._camera, self._target, self._region = camera, target, region
        self._world, self._clock, self._settings, self._log = world, clock, settings, log
        self._workers = workers
        self.source = f"collaboration:{camera.name}"
        self.frames = 0
        self.decided: float | None = None
        self._start = clock()
        self._next_frame = self._start
        self._frame: Job | None = None  # the frame being taken and searched
        self._since: Detection | None = None  # first sighting of the current still stretch

    def poll(self) -> Status:
        if not self.finished:
            try:
                self._watch()
            except Exception as exc:  # a camera or perception failure fails the node
                self.fail(f"watching for {self._target.name}: {type(exc).__name__}: {exc}")
        return super().poll()

    def _watch(self) -> None:
        frame = self._frame
        if frame is not None:
            if frame.poll() is RUNNING:
                return
            self._frame = None
            if frame.poll() is not SUCCESS:
                self.fail(f"watching for {self._target.name}: {frame.message}", frame.error)
                return
            if self._weigh(frame.outputs.get("seen")):
                return
        settings = self._settings
        now = self._clock()
        if settings.timeout > 0 and now - self._start >= settings.timeout:
            self.fail(
                f"timed out: no {self._target.name} put down in the region "
                f"within {settings.timeout:g} s",
                ErrorType.TIMEOUT,
            )
        elif now >= self._next_frame:
            self._next_frame = now + settings.interval
            what = f"watching for {self._target.name} ({self._camera.name} camera)"
            self._frame = self._workers.submit(self._look, what)

    def _look(self) -> dict[str, Detection | None]:
        """On a pool thread: a frame, searched where the region appears."""
        frame = self._camera.capture()
        self.frames += 1
        return {"seen": find_object(frame, self._target, self.source, self._region)}

    def _weigh(self, seen: Detection | None) -> bool:
        """What a frame showed; True when the object was put down (the job succeeded)."""
        self._world.replace(self.source, [seen] if seen is not None else [])
        self._since = since = self._still_since(self._since, seen)
        if seen is None or since is None or seen.stamp - since.stamp < self._settings.settle:
            return False
        self._log(
            f"{self._target.name} handed over at {_xyz(seen.pose)} (frame at {seen.stamp:.2f} s)"
        )
        self.decided = seen.stamp
        self.succeed(outputs={"pose": seen.pose})
        return True

    def _still_since(self, since: Detection | None, seen: Detection | None) -> Detection | None:
        if seen is None or not in_region(seen.pose, self._region):
            return None
        if since is None:
            return seen
        moved = math.dist(seen.pose.position, since.pose.position)
        return since if moved <= self._settings.still_tolerance else seen

    def _cancel_frame(self) -> None:
        frame = self._frame
        if frame is not None:
            frame.cancel()


def _xyz(pose: Pose) -> str:
    return "(" + ", ".join(f"{v * 1000:.0f}" for v in pose.position) + ") mm"


def object_markers(spec: Any) -> ObjectMarkers:
    """ObjectMarkers of an object library model (``ObjectModelSpec``)."""
    markers = {m.marker_id: (m.size, m.pose) for m in spec.markers}
    dims = spec.dimensions
    reach = math.hypot(dims[0] / 2, dims[1] / 2, dims[2])
    return ObjectMarkers(spec.name, markers, reach)
