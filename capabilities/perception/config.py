"""Settings of model-based recognition (SI units), with defaults for the default cell.

A cell configures them through the capability's settings (``CapabilityRegistry(settings=
{"perception": {...}})``); every key of :class:`RecognitionConfig` may be given there.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from capabilities.perception.errors import PerceptionError

__all__ = ["RecognitionConfig"]


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
        """The defaults overridden by the keys of ``settings`` that name a field."""
        names = {f.name: f for f in dataclasses.fields(cls)}
        values: dict[str, Any] = {}
        for key, value in settings.items():
            if key not in names:
                continue
            default = getattr(cls(), key)
            if isinstance(default, tuple):
                if not isinstance(value, (list, tuple)) or len(value) != len(default):
                    raise PerceptionError(f"perception setting {key!r}: expected 3 numbers")
                value = tuple(float(v) for v in value)
            elif isinstance(default, bool):
                value = bool(value)
            elif isinstance(default, (int, float)):
                value = type(default)(value)
            values[key] = value
        return dataclasses.replace(cls(), **values)
