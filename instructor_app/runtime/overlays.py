"""What the camera panel draws over a camera's pictures: detections, markers and regions.

Everything drawn comes from what the cell *believes*, never from the simulator's truth:
detected objects from the world model (written by the perception operations of a running
plan or by the panel's Detect button), markers from the marker detections in the world model,
regions from the plan. Each is projected into the image with the frame's own intrinsics and
camera pose. Objects are outlined by the 2D convex hull of their model mesh's vertices at the
detected pose, labelled with class and confidence. Drawing is OpenCV on the camera feed's
thread (:mod:`instructor_app.runtime.camera_feed`), so the GUI thread only shows pictures.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import cv2
import numpy as np

from capabilities.geometry import pose_to_matrix
from engine.types import Pose, Region

__all__ = ["OverlayPainter", "depth_image", "project", "unproject"]

_log = logging.getLogger(__name__)
_MESH_SAMPLE = 400  # outline vertices kept per object model
# BGR-free: the images are RGB, so colours are (r, g, b).
OBJECT_COLOUR = (40, 255, 80)
MARKER_COLOUR = (255, 200, 0)
REGION_COLOUR = (255, 60, 200)
DEPTH_RANGE = (0.2, 2.0)  # metres coloured from near to far


def depth_image(
    depth: np.ndarray, near: float = DEPTH_RANGE[0], far: float = DEPTH_RANGE[1]
) -> np.ndarray:
    """Metric depth as an RGB picture (near warm, far cold; no depth black)."""
    finite = np.isfinite(depth)
    scaled = np.clip((np.nan_to_num(depth, nan=far) - near) / (far - near), 0.0, 1.0)
    grey = (255 - scaled * 255).astype(np.uint8)
    coloured = cv2.applyColorMap(grey, cv2.COLORMAP_TURBO)[:, :, ::-1]
    coloured[~finite] = 0
    return np.ascontiguousarray(coloured)


def project(frame: Any, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (Nx2) of world points (Nx3) in a frame, and their depths (N) along the axis."""
    t = np.linalg.inv(pose_to_matrix(frame.T_world_camera))
    cam = np.asarray(points, dtype=float) @ t[:3, :3].T + t[:3, 3]
    z = cam[:, 2]
    safe = np.where(z > 1e-6, z, 1e-6)
    k = frame.K
    uv = np.column_stack(
        (k[0, 0] * cam[:, 0] / safe + k[0, 2], k[1, 1] * cam[:, 1] / safe + k[1, 2])
    )
    return uv, z


def unproject(frame: Any, u: float, v: float, depth: float) -> tuple[float, float, float]:
    """The world point seen at pixel (u, v) at a depth (m along the optical axis)."""
    k = frame.K
    cam = np.array([(u - k[0, 2]) * depth / k[0, 0], (v - k[1, 2]) * depth / k[1, 1], depth, 1.0])
    world = pose_to_matrix(frame.T_world_camera) @ cam
    return float(world[0]), float(world[1]), float(world[2])


def _mesh_vertices(path: Any) -> np.ndarray:
    from capabilities.open3d_lib import o3d

    mesh = o3d.io.read_triangle_mesh(str(path))  # type: ignore[arg-type]  # open3d stubs want os.PathLike; str works
    vertices = np.asarray(mesh.vertices, dtype=float)
    if len(vertices) > _MESH_SAMPLE:
        vertices = vertices[np.linspace(0, len(vertices) - 1, _MESH_SAMPLE).astype(int)]
    return vertices


class OverlayPainter:
    """Draws the cell's beliefs and the plan's regions into camera pictures.

    Args:
        world: the cell's world model (``detections()``, ``marker(id)``), or None.
        library: the object library (``get(name).mesh_file``), for outlines, or None.
        marker_sizes: marker id -> side (m) of the markers the cell knows.
    """

    def __init__(
        self,
        world: Any = None,
        library: Any = None,
        marker_sizes: Mapping[int, float] | None = None,
    ) -> None:
        self.world = world
        self.library = library
        self.marker_sizes = dict(marker_sizes or {})
        self.show_objects = True
        self.show_markers = True
        self.show_regions = True
        self._regions: tuple[tuple[str, Region], ...] = ()
        self._outlines: dict[str, np.ndarray | None] = {}

    def set_regions(self, regions: Iterable[tuple[str, Region]]) -> None:
        """The plan's regions (name, sphere); called from the GUI thread (one reference swap)."""
        self._regions = tuple(regions)

    @property
    def regions(self) -> tuple[tuple[str, Region], ...]:
        return self._regions

    def state_key(self) -> Any:
        """What the overlays drawn depend on besides the frame (switches, regions, markers and
        detections): equal keys draw the same overlays into the same frame.
        """
        world = self.world
        markers = (
            tuple(world.marker(m) for m in self.marker_sizes)
            if self.show_markers and world is not None
            else ()
        )
        found = tuple(world.detections()) if self.show_objects and world is not None else ()
        switches = (self.show_objects, self.show_markers, self.show_regions)
        return (switches, self._regions if self.show_regions else (), markers, found)

    def paint(self, frame: Any, *images: np.ndarray) -> None:
        """Draw the overlays into each image (RGB uint8, the frame's size) in place."""
        if self.show_regions:
            for name, region in self._regions:
                self._region(frame, images, name, region)
        if self.show_markers and self.world is not None:
            for marker_id, size in self.marker_sizes.items():
                seen = self.world.marker(marker_id)
                if seen is not None:
                    self._marker(frame, images, marker_id, seen[0], size)
        if self.show_objects and self.world is not None:
            for detection in self.world.detections():
                self._object(frame, images, detection)

    def _outline_points(self, object_class: str) -> np.ndarray | None:
        if object_class not in self._outlines:
            try:
                self._outlines[object_class] = _mesh_vertices(
                    self.library.get(object_class).mesh_file
                )
            except Exception as exc:  # an unknown class is drawn as a cross, not an outline
                _log.debug("no outline for %s: %s", object_class, exc)
                self._outlines[object_class] = None
        return self._outlines[object_class]

    def _object(self, frame: Any, images: Sequence[np.ndarray], detection: Any) -> None:
        model = self._outline_points(detection.object_class) if self.library is not None else None
        m = pose_to_matrix(detection.pose)
        local = model if model is not None and len(model) else np.zeros((1, 3))
        uv, z = project(frame, local @ m[:3, :3].T + m[:3, 3])
        if not np.all(z > 0.02):
            return
        pts = np.round(uv).astype(np.int32)
        label = f"{detection.object_class} {detection.confidence:.0%}"
        for image in images:
            if len(pts) >= 3:
                hull = cv2.convexHull(pts.reshape(-1, 1, 2))
                cv2.polylines(image, [hull], True, OBJECT_COLOUR, 1, cv2.LINE_8)
            else:
                cv2.drawMarker(
                    image, tuple(int(c) for c in pts[0]), OBJECT_COLOUR, cv2.MARKER_CROSS, 12
                )
            top = pts[np.argmin(pts[:, 1])]
            _text(image, label, (int(pts[:, 0].min()), int(top[1]) - 4), OBJECT_COLOUR)

    def _marker(
        self, frame: Any, images: Sequence[np.ndarray], marker_id: int, pose: Pose, size: float
    ) -> None:
        h = size / 2.0
        corners = np.array([[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]])
        m = pose_to_matrix(pose)
        uv, z = project(frame, corners @ m[:3, :3].T + m[:3, 3])
        if not np.all(z > 0.02):
            return
        pts = np.round(uv).astype(np.int32).reshape(-1, 1, 2)
        for image in images:
            cv2.polylines(image, [pts], True, MARKER_COLOUR, 1, cv2.LINE_8)
            _text(
                image,
                f"#{marker_id}",
                (int(uv[:, 0].min()), int(uv[:, 1].max()) + 10),
                MARKER_COLOUR,
            )

    def _region(self, frame: Any, images: Sequence[np.ndarray], name: str, region: Region) -> None:
        uv, z = project(frame, np.array([region.center]))
        if z[0] <= 0.02:
            return
        radius = round(frame.K[1, 1] * region.radius / z[0])
        centre = (round(uv[0, 0]), round(uv[0, 1]))
        for image in images:
            overlay = image.copy()
            cv2.circle(overlay, centre, radius, REGION_COLOUR, -1, cv2.LINE_AA)
            cv2.addWeighted(overlay, 0.25, image, 0.75, 0, dst=image)
            cv2.circle(image, centre, radius, REGION_COLOUR, 1, cv2.LINE_AA)
            _text(image, name, (centre[0] - radius, centre[1] - radius - 3), REGION_COLOUR)


def _text(
    image: np.ndarray, text: str, origin: tuple[int, int], colour: tuple[int, int, int]
) -> None:
    x, y = max(origin[0], 0), max(origin[1], 10)
    cv2.putText(image, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, 0.35, (0, 0, 0), 2, cv2.LINE_AA)
    cv2.putText(image, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, 0.35, colour, 1, cv2.LINE_AA)
