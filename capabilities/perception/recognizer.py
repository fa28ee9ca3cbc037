"""Model-based object recognition on an RGB-D frame (paper IV-B's Perceptor).

``Recognizer.recognize(frame)`` segments the table and the clusters on it
(:mod:`scene_cloud`), recognises flat clusters as plates by their holes (:mod:`plates`) and
matches the others to the library's models (:mod:`registration`), keeping the best fit that
passes the checks. Poses are reported in the world, at the model's bottom centre, z up, with
the yaw reduced by the model's symmetry (:mod:`symmetry`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from capabilities.object_library import ObjectLibrary
from capabilities.perception.config import RecognitionConfig
from capabilities.perception.geometry import (
    matrix_to_pose,
    pose_to_matrix,
    upright_matrix,
    yaw_of,
)
from capabilities.perception.models import ModelCloud, ModelSet
from capabilities.perception.plates import classify_plate, top_view
from capabilities.perception.registration import best_fit
from capabilities.perception.scene_cloud import Cluster, FrameLike, SceneCloud, segment_scene
from capabilities.perception.symmetry import canonical_yaw
from engine.types import Pose

__all__ = ["Recognition", "Recognizer"]

_HEIGHT_SLACK = 0.02  # m: a cluster may stand this much taller than the model (noise)


@dataclass(frozen=True)
class Recognition:
    """One object recognised in a frame.

    Attributes:
        object_class: the library model's name.
        pose: the object frame (bottom centre, z up) in the world.
        confidence: 0..1 (fitness times consistency for shapes; outline and holes for plates).
        details: what decided it (``fitness``, ``rmse``, ``consistency`` or ``holes``).
    """

    object_class: str
    pose: Pose
    confidence: float
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def yaw(self) -> float:
        return yaw_of(pose_to_matrix(self.pose)[:3, :3])


class Recognizer:
    """Recognises the library's objects on the table in RGB-D frames; thread-safe.

    Args:
        library: the object models.
        config: recognition settings.
    """

    def __init__(self, library: ObjectLibrary, config: RecognitionConfig | None = None) -> None:
        self.config = config or RecognitionConfig()
        self.models = ModelSet(library, self.config.voxel)
        self.last_seconds = 0.0

    def recognize(self, frame: FrameLike) -> list[Recognition]:
        """The objects in ``frame``; raise PerceptionError when no table is in view."""
        start = time.perf_counter()
        scene = segment_scene(frame, self.config)
        models = self.models.all()
        plates = [m for m in models if m.holes]
        shapes = [m for m in models if not m.holes and m.height >= self.config.flat_height]
        found = []
        for cluster in scene.clusters:
            if cluster.top < self.config.flat_height:
                hit = self._plate(scene, cluster, plates)
            else:
                hit = self._shape(scene, cluster, shapes)
            if hit is not None:
                found.append(hit)
        self.last_seconds = time.perf_counter() - start
        return found

    def _world(self, scene: SceneCloud, model: ModelCloud, x: float, y: float, yaw: float) -> Pose:
        yaw = canonical_yaw(yaw, model.spec.symmetry)
        return matrix_to_pose(scene.T_world_table @ upright_matrix(x, y, yaw))

    def _plate(
        self, scene: SceneCloud, cluster: Cluster, plates: list[ModelCloud]
    ) -> Recognition | None:
        view = top_view(scene, cluster, self.config)
        plate = classify_plate(view, plates) if view is not None else None
        if plate is None:
            return None
        model = self.models.get(plate.model)
        pose = self._world(scene, model, plate.x, plate.y, plate.yaw)
        return Recognition(plate.model, pose, plate.confidence, {"holes": plate.holes})

    def _shape(
        self, scene: SceneCloud, cluster: Cluster, shapes: list[ModelCloud]
    ) -> Recognition | None:
        extent = float(np.ptp(cluster.points[:, :2], axis=0).max())
        plausible = []
        for model in shapes:
            dims = model.spec.dimensions
            too_tall = cluster.top > model.height + _HEIGHT_SLACK
            too_wide = extent > float(np.hypot(dims[0], dims[1])) + 0.03
            if not (too_tall or too_wide or cluster.top < 0.4 * model.height):
                plausible.append(model)
        best = best_fit(scene, cluster, plausible, self.config) if plausible else None
        cfg = self.config
        if best is None or best.fitness < cfg.min_fitness or best.consistency < cfg.min_consistency:
            return None
        pose = self._world(scene, self.models.get(best.model), best.x, best.y, best.yaw)
        details = {"fitness": best.fitness, "rmse": best.rmse, "consistency": best.consistency}
        return Recognition(best.model, pose, best.score, details)
