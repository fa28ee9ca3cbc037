"""Pointing in the 3D scene: a click gives the surface point under the mouse (the point
cloud, else the table top), and in region mode a press sets a region's centre and the drag
its radius (in the plane through the centre facing the view).

A mixin of :class:`instructor_app.panels.scene3d.Scene3DPanel`, kept apart to keep that
module short; it uses the panel's ``point_picked``, ``region_drawn`` and ``message`` signals,
``table_z``, the latest cloud points and ``_replace`` for the draft sphere.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from engine.types import Region
from instructor_app.panels.scene3d_items import ray_hit_plane, ray_hit_points, sphere_item

__all__ = ["PointingMixin"]


class PointingMixin:
    """Click-to-point and drag-a-region for the 3D scene panel."""

    point_picked: Any
    region_drawn: Any
    message: Any
    table_z: float
    _draft: tuple[np.ndarray, np.ndarray] | None

    def _replace(self, group: str, items: list[Any]) -> None:  # the panel's
        raise NotImplementedError

    def pick(self, origin: np.ndarray, direction: np.ndarray) -> np.ndarray | None:
        """The surface point a ray meets first: the point cloud, else the table top."""
        hit = ray_hit_points(
            origin, direction, getattr(self, "_cloud_points", np.zeros((0, 3))), 0.008
        )
        if hit is not None:
            return hit
        table = np.array([0.0, 0.0, self.table_z])
        return ray_hit_plane(origin, direction, table, np.array([0.0, 0.0, 1.0]))

    def _on_click(self, origin: Any, direction: Any) -> None:
        hit = self.pick(origin, direction)
        if hit is not None:
            self.point_picked.emit(tuple(float(v) for v in hit))
            self.message.emit("Point: ({:.0f}, {:.0f}, {:.0f}) mm".format(*(hit * 1000)))

    def _on_press(self, origin: Any, direction: Any) -> None:
        hit = self.pick(origin, direction)
        self._draft = None if hit is None else (hit, -direction)
        self._replace("draft", [])

    def _draft_radius(self, origin: np.ndarray, direction: np.ndarray) -> float:
        if self._draft is None:
            return 0.0
        centre, normal = self._draft
        edge = ray_hit_plane(origin, direction, centre, normal)
        return 0.0 if edge is None else float(np.linalg.norm(edge - centre))

    def _on_drag(self, origin: Any, direction: Any) -> None:
        radius = self._draft_radius(origin, direction)
        if self._draft is not None and radius > 0.005:
            sphere = sphere_item(radius, (1.0, 0.25, 0.8, 0.35))
            sphere.translate(*self._draft[0])
            self._replace("draft", [sphere])

    def _on_release(self, origin: Any, direction: Any) -> None:
        radius = self._draft_radius(origin, direction)
        centre = self._draft[0] if self._draft is not None else None
        self._draft = None
        self._replace("draft", [])
        if centre is None or radius < 0.01:
            self.message.emit("Press on a surface and drag out the region's radius (at least 1 cm)")
            return
        x, y, z = (float(v) for v in centre)
        self.region_drawn.emit(Region((x, y, z), radius))
