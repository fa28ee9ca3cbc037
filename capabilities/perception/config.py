"""Settings of model-based recognition (SI units), with defaults for the default cell.

A cell configures them in its file's ``capabilities.perception`` block; every field of
:class:`RecognitionConfig` is a setting (:data:`SETTINGS`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from capabilities.kit import Setting

__all__ = ["SETTINGS", "RecognitionConfig"]


@dataclass(frozen=True)
class RecognitionConfig:
    """How recognition looks at a frame.

    Attributes:
        workspace_min, workspace_max: world box (m) around the table; points outside are
            ignored (the floor, the robot's stand, the room).
        stride: use every ``stride``-th pixel of images wider than 400 px (1 for smaller).
        plane_threshold: distance (m) of a point to the table plane to count as table.
        min_height, max_height: object points lie this high above the table (m).
        voxel: grid (m) the object points are thinned to before clustering and matching.
        cluster_eps: DBSCAN neighbourhood (m); min_cluster_points: smaller clusters are noise.
        flat_height: a cluster lower than this (m) is a flat part (a plate): it is recognised
            from its outline and holes in a top view.
        top_view_resolution: m per pixel of that top view.
        min_hole_area: a hole in the top view smaller than this (m^2) is noise.
        inlier_distance: a scene point closer than this (m) to the fitted model counts.
        free_space_tolerance: a model surface this far (m) in front of what the camera saw
            contradicts the image.
        min_fitness, min_consistency: a fit below either is rejected.
        global_registration: add FPFH + RANSAC hypotheses to the footprint-based ones.
    """

    workspace_min: tuple[float, float, float] = (0.1, -0.65, -0.1)
    workspace_max: tuple[float, float, float] = (1.0, 0.65, 0.5)
    stride: int = 2
    plane_threshold: float = 0.004
    min_height: float = 0.002
    max_height: float = 0.45
    voxel: float = 0.005
    cluster_eps: float = 0.015
    min_cluster_points: int = 20
    flat_height: float = 0.015
    top_view_resolution: float = 0.001
    min_hole_area: float = 25e-6
    inlier_distance: float = 0.006
    free_space_tolerance: float = 0.012
    min_fitness: float = 0.7
    min_consistency: float = 0.8
    global_registration: bool = True

    @classmethod
    def from_settings(cls, settings: Mapping[str, Any]) -> RecognitionConfig:
        """The configuration from the capability's checked settings (see :data:`SETTINGS`)."""
        names = {f.name for f in dataclasses.fields(cls)}
        return dataclasses.replace(cls(), **{k: v for k, v in settings.items() if k in names})


def _setting(field: dataclasses.Field[Any]) -> Setting:
    default = field.default
    if isinstance(default, tuple):
        return Setting(field.name, tuple, default, "see RecognitionConfig", len(default))
    return Setting(field.name, type(default), default, "see RecognitionConfig")


SETTINGS = tuple(_setting(f) for f in dataclasses.fields(RecognitionConfig))
"""The perception capability's settings: every field of :class:`RecognitionConfig`."""
