"""Thumbnails of object models, drawn without OpenGL and kept in a cache folder.

A small orthographic picture of the mesh from above and to the side: the triangles are
projected with numpy, shaded flat (a light from the viewer's side) in the model's colour
and filled far-to-near with OpenCV (anti-aliased, at twice the size, then scaled down).
The mesh is read with Open3D. Nothing here touches Qt: the panel calls :meth:`get` on a
worker thread. A thumbnail is cached as a PNG named by the mesh file, its size and time
of change, the colour and the picture size, so an edited mesh gets a new one.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import cv2
import numpy as np

from capabilities.object_library import ObjectModelSpec
from engine.files import PlanFileError
from engine.plan_writer import write_atomic

__all__ = ["ThumbnailCache", "render_mesh", "render_thumbnail"]

_VIEW = np.array([1.0, -1.3, 1.0]) / np.linalg.norm([1.0, -1.3, 1.0])  # towards the viewer
_LIGHT = np.array([0.4, -0.6, 1.0]) / np.linalg.norm([0.4, -0.6, 1.0])
_SHIFT = 4  # sub-pixel bits of the polygon corners


def render_mesh(
    vertices: np.ndarray, triangles: np.ndarray, color: tuple[float, ...], size: int = 96
) -> np.ndarray:
    """An RGBA picture (size x size, uint8) of a triangle mesh; transparent around it."""
    scale_up = 2
    big = size * scale_up
    forward = -_VIEW
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    points = np.stack([vertices @ right, -(vertices @ up)], axis=1)  # image y grows down
    depth = vertices @ forward
    low, high = points.min(axis=0), points.max(axis=0)
    extent = float(max(high - low)) or 1.0
    pixels = (points - (low + high) / 2) * (0.86 * big / extent) + big / 2
    corners = np.round(pixels[triangles] * (1 << _SHIFT)).astype(np.int32)
    normals = np.cross(
        vertices[triangles[:, 1]] - vertices[triangles[:, 0]],
        vertices[triangles[:, 2]] - vertices[triangles[:, 0]],
    )
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = normals / np.where(lengths > 0, lengths, 1.0)
    normals[normals @ forward > 0] *= -1  # two-sided: the face seen
    shade = 0.35 + 0.65 * np.clip(normals @ _LIGHT, 0.0, 1.0)
    base = np.array(color[:3], dtype=float) * 255
    image = np.zeros((big, big, 4), dtype=np.uint8)
    for index in np.argsort(-depth[triangles].mean(axis=1)):  # far ones first
        r, g, b = (base * shade[index]).clip(0, 255)
        cv2.fillConvexPoly(
            image, corners[index], (int(b), int(g), int(r), 255), cv2.LINE_AA, _SHIFT
        )
    small = cv2.resize(image, (size, size), interpolation=cv2.INTER_AREA)
    return cv2.cvtColor(small, cv2.COLOR_BGRA2RGBA)


def render_thumbnail(spec: ObjectModelSpec, size: int = 96) -> np.ndarray:
    """The RGBA thumbnail of a model's mesh (read with Open3D)."""
    from capabilities.open3d_lib import o3d  # a large import: only on the worker thread that draws

    mesh = o3d.io.read_triangle_mesh(str(spec.mesh_file))  # type: ignore[arg-type]  # str works
    vertices = np.asarray(mesh.vertices, dtype=float)
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    if len(triangles) == 0:
        raise ValueError(f"{spec.mesh_file}: no triangles to draw")
    return render_mesh(vertices, triangles, spec.color, size)


class ThumbnailCache:
    """Thumbnails on disk: drawn once per mesh version.

    Args:
        folder: where the PNG files go (made when needed); None: draw every time.
        size: the thumbnails' side in pixels.
    """

    def __init__(self, folder: Path | None, size: int = 64) -> None:
        self.folder = folder
        self.size = size
        self.drawn = 0  # how many were drawn, not read from the cache (for tests)

    def _key(self, spec: ObjectModelSpec) -> str:
        stat = spec.mesh_file.stat()
        text = (
            f"{spec.mesh_file.resolve()}|{stat.st_size}|{stat.st_mtime_ns}|{spec.color}|{self.size}"
        )
        return hashlib.sha1(text.encode("utf-8")).hexdigest()[:20]

    def get(self, spec: ObjectModelSpec) -> np.ndarray:
        """The model's RGBA thumbnail, from the cache or drawn (and then cached)."""
        path = self.folder / f"{spec.name}-{self._key(spec)}.png" if self.folder else None
        if path is not None and path.is_file():
            cached = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
            if cached is not None and cached.shape == (self.size, self.size, 4):
                return cv2.cvtColor(cached, cv2.COLOR_BGRA2RGBA)
        picture = render_thumbnail(spec, self.size)
        self.drawn += 1
        if path is not None:
            ok, png = cv2.imencode(".png", cv2.cvtColor(picture, cv2.COLOR_RGBA2BGRA))
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                if ok:
                    write_atomic(path, png.tobytes())
            except (OSError, PlanFileError):
                pass  # a cache that cannot be written only costs a redraw next time
        return picture
