"""Keeping object identities from frame to frame (the paper's surface-segmentation tracking).

Each recognition is associated with the track of the same class nearest to it, within a
gate; tracks take the new pose, and a recognition nobody claims starts a new track with a
new id ("cup#1", "cup#2", ...). The previous yaw of a track is the reference of the
symmetry reduction, so that a symmetric object keeps a steady canonical pose.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from capabilities.object_library import Symmetry
from capabilities.perception.geometry import matrix_to_pose, pose_to_matrix, yaw_of
from capabilities.perception.recognizer import Recognition
from capabilities.perception.symmetry import canonical_yaw
from engine.types import Pose

__all__ = ["SurfaceTracker", "Track"]


@dataclass
class Track:
    """An object followed over frames: its id, class, last pose and when it was seen."""

    instance: str
    object_class: str
    pose: Pose
    stamp: float
    missed: int = 0


class SurfaceTracker:
    """Associates recognitions with tracks by nearest position; thread-safe.

    Args:
        gate: a recognition farther than this (m) from every track of its class is new.
        max_missed: a track not seen in this many updates in a row is forgotten.
        symmetries: class -> symmetry, to keep a symmetric object's yaw steady.
    """

    def __init__(
        self,
        gate: float = 0.05,
        max_missed: int = 3,
        symmetries: Mapping[str, Symmetry] | None = None,
    ) -> None:
        self.gate = gate
        self.max_missed = max_missed
        self._symmetries = dict(symmetries or {})
        self._tracks: list[Track] = []
        self._counters: dict[str, int] = {}
        self._lock = threading.Lock()

    @property
    def tracks(self) -> list[Track]:
        with self._lock:
            return list(self._tracks)

    def update(
        self, recognitions: Sequence[Recognition], stamp: float
    ) -> list[tuple[str, Recognition]]:
        """(instance id, recognition with its pose made steady) for each recognition."""
        with self._lock:
            pairs = self._associate(recognitions)
            out: list[tuple[str, Recognition]] = []
            claimed = set()
            for i, recognition in enumerate(recognitions):
                track = pairs.get(i)
                if track is None:
                    track = self._new_track(recognition, stamp)
                else:
                    recognition = self._steady(recognition, track)
                track.pose, track.stamp, track.missed = recognition.pose, stamp, 0
                claimed.add(track.instance)
                out.append((track.instance, recognition))
            for track in self._tracks:
                if track.instance not in claimed:
                    track.missed += 1
            self._tracks = [t for t in self._tracks if t.missed <= self.max_missed]
            return out

    def _associate(self, recognitions: Sequence[Recognition]) -> dict[int, Track]:
        """Greedy nearest-first matching of recognitions to tracks of the same class."""
        options = sorted(
            (math.dist(r.pose.position, t.pose.position), i, j)
            for i, r in enumerate(recognitions)
            for j, t in enumerate(self._tracks)
            if t.object_class == r.object_class
        )
        pairs: dict[int, Track] = {}
        used: set[int] = set()
        for distance, i, j in options:
            if distance > self.gate:
                break
            if i not in pairs and j not in used:
                pairs[i] = self._tracks[j]
                used.add(j)
        return pairs

    def _new_track(self, recognition: Recognition, stamp: float) -> Track:
        n = self._counters.get(recognition.object_class, 0) + 1
        self._counters[recognition.object_class] = n
        track = Track(
            f"{recognition.object_class}#{n}", recognition.object_class, recognition.pose, stamp
        )
        self._tracks.append(track)
        return track

    def _steady(self, recognition: Recognition, track: Track) -> Recognition:
        """The recognition with its yaw reduced by symmetry toward the track's last yaw."""
        symmetry = self._symmetries.get(recognition.object_class)
        if symmetry is None or symmetry.kind == "none":
            return recognition
        m = pose_to_matrix(recognition.pose)
        previous = yaw_of(pose_to_matrix(track.pose)[:3, :3])
        turn = canonical_yaw(yaw_of(m[:3, :3]), symmetry, previous) - yaw_of(m[:3, :3])
        c, s = math.cos(turn), math.sin(turn)
        about_z = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
        m[:3, :3] = m[:3, :3] @ about_z  # a turn about the object's own (symmetry) axis
        return replace(recognition, pose=matrix_to_pose(m))
