"""Spatial relations and motion from poses (numpy only): the Predicator's geometry.

Directions are measured along the axes of a frame of reference: in front = +x, behind = -x,
left = +y, right = -y, up = +z, down = -z. The frame is the world's, the robot base's, or
the second object's own; only its orientation matters, the offset is between the centres
of the objects' bounding boxes.
"""

from __future__ import annotations

import collections
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from capabilities.predicates.settings import DIRECTIONS
from capabilities.robot_body import pose_matrix
from engine.types import Pose

__all__ = ["DIRECTIONS", "PoseTrack", "Motion", "offset_in_frame", "box_center"]


def box_center(pose: Pose, height: float) -> np.ndarray:
    """World centre of an object's bounding box (its frame is at the bottom centre)."""
    return pose_matrix(pose)[:3, :3] @ np.array([0.0, 0.0, height / 2]) + pose.position


def offset_in_frame(a: np.ndarray, b: np.ndarray, frame: Pose) -> np.ndarray:
    """The vector from ``b`` to ``a`` (world points) along the axes of ``frame``."""
    return pose_matrix(frame)[:3, :3].T @ (np.asarray(a) - np.asarray(b))


@dataclass(frozen=True)
class Motion:
    """How an object moved over a window: ``samples`` poses, fitted ``speed`` (m/s)."""

    samples: int
    span: float
    speed: float


class PoseTrack:
    """A short history of one object's detected positions, one per detection stamp.

    Args:
        keep: seconds of history to keep (older samples are dropped).
    """

    def __init__(self, keep: float = 10.0) -> None:
        self._keep = keep
        self._samples: collections.deque[tuple[float, tuple[float, float, float]]] = (
            collections.deque()
        )

    def observe(self, stamp: float, position: Sequence[float]) -> None:
        """Add a detection (a repeated stamp is the same detection and is ignored)."""
        if self._samples and stamp <= self._samples[-1][0]:
            return
        self._samples.append((stamp, (float(position[0]), float(position[1]), float(position[2]))))
        while self._samples and self._samples[0][0] < stamp - self._keep:
            self._samples.popleft()

    def motion(self, since: float) -> Motion:
        """The least-squares velocity of the samples stamped at or after ``since``."""
        recent = [(t, pos) for t, pos in self._samples if t >= since]
        if len(recent) < 2:
            return Motion(len(recent), 0.0, 0.0)
        t = np.array([s[0] for s in recent])
        xyz = np.array([s[1] for s in recent])
        centred = t - t.mean()
        velocity = centred @ (xyz - xyz.mean(axis=0)) / float(centred @ centred)
        return Motion(len(recent), float(t[-1] - t[0]), float(np.linalg.norm(velocity)))
