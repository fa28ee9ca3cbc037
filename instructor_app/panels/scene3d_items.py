"""What the 3D scene draws, as pyqtgraph.opengl items: the robot from its meshes, boxes,
spheres, named axes, camera frusta, and the ray geometry that turns a click into a point.

Meshes are read with Open3D (``o3d.io.read_triangle_mesh``), never a parser of our own: the
UR5's links from example-robot-data (its collision STLs: Open3D reads no COLLADA), objects
from the object library. Link poses come from :class:`capabilities.robot_body.RobotBody` (the
UR5's forward kinematics), so the arm is drawn from the joints a real cell reports as well.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyqtgraph as pg
import pyqtgraph.opengl as gl

from capabilities.geometry import pose_to_matrix
from capabilities.robot_body import LINK_NAMES, RobotBody
from engine.types import Pose

__all__ = [
    "RobotItems",
    "axes_item",
    "box_item",
    "frustum_lines",
    "mesh_data",
    "ray_hit_points",
    "ray_hit_plane",
    "set_pose",
    "sphere_item",
]

# example-robot-data mesh of each UR5 link (the tool0 frame has none).
_LINK_MESHES = {
    "base_link": "base",
    "shoulder_link": "shoulder",
    "upper_arm_link": "upperarm",
    "forearm_link": "forearm",
    "wrist_1_link": "wrist1",
    "wrist_2_link": "wrist2",
    "wrist_3_link": "wrist3",
}


def _ur5_mesh_dir() -> Path:
    from capabilities.robot.robot_model import ur5_collision_meshes

    return ur5_collision_meshes()


@functools.lru_cache(maxsize=64)
def mesh_data(path: str) -> gl.MeshData:
    """The triangles of a mesh file as MeshData (read once per file)."""
    from capabilities.open3d_lib import o3d

    mesh = o3d.io.read_triangle_mesh(path)  # type: ignore[arg-type]  # open3d stubs want os.PathLike; str works
    if len(mesh.triangles) == 0:
        raise ValueError(f"{path}: no triangles")
    return gl.MeshData(
        vertexes=np.asarray(mesh.vertices, dtype=np.float32),
        faces=np.asarray(mesh.triangles, dtype=np.int32),
    )


def set_pose(item: Any, matrix: np.ndarray) -> None:
    """Place a GL item by a 4x4 world matrix."""
    item.setTransform(pg.Transform3D(*np.asarray(matrix, dtype=float).ravel()))


class RobotItems:
    """The UR5 as one mesh item per link, placed by forward kinematics.

    Args:
        view: the GLViewWidget to add the items to.
        base: the robot base frame in the world.
        colour: RGBA 0..1 (a ghost arm is translucent).
    """

    def __init__(
        self, view: Any, base: Pose, colour: tuple[float, ...] = (0.75, 0.78, 0.82, 1.0)
    ) -> None:
        self.body = RobotBody(base)
        self.items: dict[str, gl.GLMeshItem] = {}
        self.joints: tuple[float, ...] | None = None
        translucent = colour[3] < 1.0
        folder = _ur5_mesh_dir()
        for link, stem in _LINK_MESHES.items():
            item = gl.GLMeshItem(
                meshdata=mesh_data(str(folder / f"{stem}.stl")),
                color=colour,
                smooth=False,
                shader="shaded",
                glOptions="translucent" if translucent else "opaque",
            )
            view.addItem(item)
            self.items[link] = item
        self.tool = gl.GLMeshItem(
            meshdata=gl.MeshData.cylinder(rows=1, cols=16, radius=[0.035, 0.035], length=0.12),
            color=(0.3, 0.3, 0.35, colour[3]),
            shader="shaded",
            glOptions="translucent" if translucent else "opaque",
        )
        view.addItem(self.tool)

    def set_joints(self, q: Sequence[float]) -> np.ndarray:
        """Pose the links at joints ``q``; returns the flange (tool0) matrix."""
        frames = self.body.link_matrices(q)
        for name, m in zip(LINK_NAMES, frames, strict=True):
            if name in self.items:
                set_pose(self.items[name], m)
        set_pose(self.tool, frames[-1])
        self.joints = tuple(q)
        return frames[-1]

    def set_visible(self, visible: bool) -> None:
        for item in (*self.items.values(), self.tool):
            item.setVisible(visible)


def box_item(size: Sequence[float], colour: tuple[float, ...]) -> gl.GLMeshItem:
    """A box of ``size`` (x, y, z) centred on its frame."""
    sx, sy, sz = (float(v) / 2 for v in size)
    corners = np.array(
        [[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)], dtype=np.float32
    )
    faces = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
    ], dtype=np.int32)  # fmt: skip  # a table: two triangles per side of the box
    return gl.GLMeshItem(vertexes=corners, faces=faces, color=colour, shader="shaded", smooth=False)


def sphere_item(radius: float, colour: tuple[float, ...]) -> gl.GLMeshItem:
    """A translucent sphere (a region)."""
    data = gl.MeshData.sphere(rows=16, cols=24, radius=radius)
    return gl.GLMeshItem(
        meshdata=data, color=colour, shader="shaded", glOptions="translucent", smooth=True
    )


def axes_item(length: float = 0.06, width: float = 2.0) -> gl.GLLinePlotItem:
    """Red, green and blue segments along a frame's x, y and z (place it with set_pose)."""
    pts = np.array(
        [[0, 0, 0], [length, 0, 0], [0, 0, 0], [0, length, 0], [0, 0, 0], [0, 0, length]],
        dtype=float,
    )
    colours = np.array(
        [[1, 0, 0, 1]] * 2 + [[0, 1, 0, 1]] * 2 + [[0.2, 0.4, 1, 1]] * 2, dtype=float
    )
    return gl.GLLinePlotItem(pos=pts, color=colours, width=width, mode="lines", antialias=True)


def frustum_lines(
    K: np.ndarray, size: tuple[int, int], pose: Pose, depth: float = 0.25
) -> np.ndarray:
    """Line segments (2N x 3, world) of a camera's view pyramid ``depth`` m deep."""
    w, h = size
    corners = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
    far = [
        ((u - K[0, 2]) * depth / K[0, 0], (v - K[1, 2]) * depth / K[1, 1], depth)
        for u, v in corners
    ]
    segments = []
    for i, corner in enumerate(far):
        segments += [(0.0, 0.0, 0.0), corner, corner, far[(i + 1) % 4]]
    m = pose_to_matrix(pose)
    pts = np.asarray(segments, dtype=float)
    return pts @ m[:3, :3].T + m[:3, 3]


def ray_hit_points(
    origin: np.ndarray, direction: np.ndarray, points: np.ndarray, tolerance: float = 0.01
) -> np.ndarray | None:
    """The point of a cloud nearest the eye among those within ``tolerance`` m of a ray."""
    if points is None or len(points) == 0:
        return None
    d = direction / np.linalg.norm(direction)
    rel = points - origin
    along = rel @ d
    off = np.linalg.norm(rel - np.outer(along, d), axis=1)
    near = np.nonzero((off <= tolerance) & (along > 0))[0]
    if near.size == 0:
        return None
    return np.asarray(points[near[np.argmin(along[near])]], dtype=float)


def ray_hit_plane(
    origin: np.ndarray, direction: np.ndarray, point: np.ndarray, normal: np.ndarray
) -> np.ndarray | None:
    """Where a ray meets a plane (None when parallel or behind the eye)."""
    denom = float(np.dot(direction, normal))
    if abs(denom) < 1e-9:
        return None
    t = float(np.dot(np.asarray(point) - origin, normal)) / denom
    return None if t <= 0 else origin + t * direction
