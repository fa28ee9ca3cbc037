"""Scoring recognitions against ground truth (for tests and benchmarks only).

Every true object is matched to the closest recognition of the same class; it counts as
recognised when that one is within the position and rotation tolerances, the rotation
error taking the model's symmetry into account.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from capabilities.object_library import ObjectLibrary
from capabilities.perception.geometry import pose_to_matrix
from capabilities.perception.models import ModelCloud
from capabilities.perception.recognizer import Recognition
from capabilities.perception.scene_cloud import FrameLike
from capabilities.perception.symmetry import pose_error
from engine.types import Pose

__all__ = ["ObjectScore", "score_recognitions", "visible_fraction"]


@dataclass(frozen=True)
class ObjectScore:
    """How one true object was recognised.

    Attributes:
        name, model: the object's name in the scene and its library model.
        found: recognised with the right class within the tolerances.
        position_error, rotation_error: of the closest same-class recognition (m, rad;
            inf when there is none).
        nearest_class: the class of the closest recognition of any class within
            ``class_radius`` ("" if none): what a classifier said about this object.
    """

    name: str
    model: str
    found: bool
    position_error: float
    rotation_error: float
    nearest_class: str


def score_recognitions(
    recognitions: Sequence[Recognition],
    truth: Mapping[str, tuple[str, Pose]],
    library: ObjectLibrary,
    max_position: float = 0.02,
    max_rotation: float = math.radians(10),
    class_radius: float = 0.03,
) -> list[ObjectScore]:
    """Score ``recognitions`` against ``truth`` (object name -> (model, true pose))."""
    scores = []
    for name, (model, pose) in truth.items():
        symmetry = library.get(model).symmetry
        same = [r for r in recognitions if r.object_class == model]
        errors = [pose_error(r.pose, pose, symmetry) for r in same]
        pos, rot = min(errors, default=(math.inf, math.inf))
        near = [(math.dist(r.pose.position, pose.position), r.object_class) for r in recognitions]
        nearest = min(near, default=(math.inf, ""))
        scores.append(
            ObjectScore(
                name,
                model,
                pos <= max_position and rot <= max_rotation,
                pos,
                rot,
                nearest[1] if nearest[0] <= class_radius else "",
            )
        )
    return scores


def visible_fraction(frame: FrameLike, model: ModelCloud, pose: Pose) -> float:
    """Share of the model's camera-facing surface at ``pose`` (world) that the frame sees
    (its depth within 1 cm of the surface): 0 hidden or out of view, ~1 in plain view.
    """
    t = pose_to_matrix(pose)
    pts = model.points @ t[:3, :3].T + t[:3, 3]
    nrm = model.normals @ t[:3, :3].T
    camera = pose_to_matrix(frame.T_world_camera)
    facing = ((camera[:3, 3] - pts) * nrm).sum(axis=1) > 0
    inv = np.linalg.inv(camera)
    cam = pts[facing] @ inv[:3, :3].T + inv[:3, 3]
    cam = cam[cam[:, 2] > 0.05]
    if len(cam) == 0:
        return 0.0
    k = frame.K
    u = np.rint(k[0, 0] * cam[:, 0] / cam[:, 2] + k[0, 2]).astype(int)
    v = np.rint(k[1, 1] * cam[:, 1] / cam[:, 2] + k[1, 2]).astype(int)
    h, w = frame.depth.shape
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    seen = np.full(len(cam), np.nan)
    seen[inside] = frame.depth[v[inside], u[inside]]
    return float(np.mean(np.abs(seen - cam[:, 2]) < 0.01))
