"""What the predicates of one cell share: pose histories and the private collision world.

One :class:`PredicatesState` per cell, made by the capability's ``setup`` hook; its
settings (:data:`SETTINGS`) come from the cell file's ``capabilities.predicates`` block.
"""

from __future__ import annotations

import threading
from typing import Any

from capabilities.base import CapabilityEnv
from capabilities.predicates.collision import CollisionWorld, PredicateError
from capabilities.predicates.geometry import PoseTrack
from capabilities.predicates.settings import SETTINGS
from capabilities.robot_body import RobotBodyError, robot_base_from_arm
from capabilities.world_model import Detection
from engine.types import ObjectModel, Pose

__all__ = ["SETTINGS", "PredicatesState", "setup"]


class PredicatesState:
    """The shared predicate machinery of one cell."""

    def __init__(self, env: CapabilityEnv) -> None:
        settings = env.settings  # checked against SETTINGS: typed, defaults filled in
        self.world = env.interface("world")
        self.library = env.interface("objects")
        self.arm = env.cell.interfaces().get("arm")
        self._settings = settings
        self._lock = threading.Lock()
        self._history: float = settings["history"]
        self._tracks: dict[str, PoseTrack] = {}
        self._collision: CollisionWorld | None = None
        self._base: Pose | None = None

    def sample(self) -> None:
        """Add the world model's current best detection of every class to its history.

        Called at every predicate evaluation: the history holds every detection that was
        current at some evaluation (a detection replaced between two is not seen).
        """
        seen: set[str] = set()
        for detection in self.world.detections():  # best first
            if detection.object_class in seen:
                continue
            seen.add(detection.object_class)
            with self._lock:
                track = self._tracks.setdefault(detection.object_class, PoseTrack(self._history))
                track.observe(detection.stamp, detection.pose.position)

    def track(self, name: str) -> PoseTrack:
        with self._lock:
            return self._tracks.setdefault(name, PoseTrack(self._history))

    def best(self, model: Any) -> Detection:
        """The world model's best detection of an object; raises PredicateError if unseen."""
        name = model.name if isinstance(model, ObjectModel) else str(model)
        found = self.world.best(name)
        if found is None:
            raise PredicateError(f"{name} has not been seen")
        return found

    def height(self, name: str) -> float:
        """Bounding-box height of a model (0 for a model the library does not know)."""
        try:
            return float(self.library.get(name).dimensions[2])
        except Exception:  # a detection of a class without a model: use its frame origin
            return 0.0

    def robot_base(self) -> Pose:
        with self._lock:
            if self._base is None:
                try:
                    self._base = robot_base_from_arm(self.arm, self._settings["robot_base"])
                except (RobotBodyError, AttributeError) as exc:
                    raise PredicateError(f"the robot's base frame is unknown: {exc}") from exc
            return self._base

    def tool_pose(self) -> Pose:
        if self.arm is None:
            raise PredicateError("the cell has no arm: the tool's pose is unknown")
        return self.arm.tcp_pose()

    def collision(self) -> CollisionWorld:
        with self._lock:
            if self._collision is None:
                size, center = self._settings["tool_size"], self._settings["tool_center"]
                self._collision = CollisionWorld(self.library, size, center)
            return self._collision


def setup(env: CapabilityEnv) -> PredicatesState:
    """The capability's per-cell hook: the state all predicates of a cell share."""
    return PredicatesState(env)
