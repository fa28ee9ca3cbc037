"""What the cell currently believes about the world: detected objects and markers.

Perception operations write here (a marker detection, a model-based recognition); motion
operations read here to compose a waypoint taught relative to an object with where that
object was last seen. It is the paper's "continuous output" (phi) of the perception
capabilities that other capabilities take as input (gamma). One instance per cell session.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from dataclasses import dataclass

from engine.types import Pose

__all__ = ["Detection", "WorldModel"]


@dataclass(frozen=True)
class Detection:
    """One object seen: its class (an object library name), pose in the world, confidence.

    Attributes:
        object_class: the object model's name ("cup").
        pose: the object frame in the world frame.
        confidence: 0..1.
        stamp: the cell's clock when the image was taken.
        source: what saw it ("markers:shoulder", "perceptor:wrist").
        instance: an identity kept from frame to frame by a tracker ("" if none).
    """

    object_class: str
    pose: Pose
    confidence: float
    stamp: float
    source: str
    instance: str = ""


class WorldModel:
    """Latest detections per source, and marker poses; safe to use from any thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._by_source: dict[str, list[Detection]] = {}
        self._markers: dict[int, tuple[Pose, float]] = {}

    def replace(self, source: str, detections: Iterable[Detection]) -> None:
        """What ``source`` sees now replaces what it saw before (an object gone is gone)."""
        with self._lock:
            self._by_source[source] = list(detections)

    def detections(self, object_class: str | None = None) -> list[Detection]:
        """All current detections (of one class), best first."""
        with self._lock:
            found = [d for ds in self._by_source.values() for d in ds]
        if object_class is not None:
            found = [d for d in found if d.object_class == object_class]
        return sorted(found, key=lambda d: (-d.confidence, -d.stamp))

    def best(self, object_class: str, newer_than: float | None = None) -> Detection | None:
        """The most confident current detection of a class (optionally not older than a time)."""
        for detection in self.detections(object_class):
            if newer_than is None or detection.stamp >= newer_than:
                return detection
        return None

    def set_markers(self, poses: dict[int, Pose], stamp: float) -> None:
        with self._lock:
            for marker_id, pose in poses.items():
                self._markers[marker_id] = (pose, stamp)

    def marker(self, marker_id: int) -> tuple[Pose, float] | None:
        """(pose in the world, stamp) of a marker last seen, or None."""
        with self._lock:
            return self._markers.get(marker_id)

    def markers(self) -> dict[int, tuple[Pose, float]]:
        """Every marker seen: id -> (pose in the world, stamp)."""
        with self._lock:
            return dict(self._markers)

    def clear(self) -> None:
        with self._lock:
            self._by_source.clear()
            self._markers.clear()
