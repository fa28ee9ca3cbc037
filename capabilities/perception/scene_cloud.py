"""From an RGB-D frame to object clusters on the table.

Steps: world points of the pixels, cropped to the workspace; the table plane by RANSAC
(Open3D), refined by least squares; heights above it; the points above the table thinned to
a voxel grid and split into clusters by DBSCAN. Everything after this works in the *table
frame* (z up from the fitted plane), where an object on the table is (x, y, yaw).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from capabilities.open3d_lib import o3d
from capabilities.perception.config import RecognitionConfig
from capabilities.perception.errors import PerceptionError
from capabilities.perception.geometry import pose_to_matrix, table_frame
from engine.types import Pose

__all__ = ["Cluster", "FrameLike", "SceneCloud", "segment_scene"]

_PLANE_SAMPLE = 20000
_NORMAL_NEIGHBOURS = 12


class FrameLike(Protocol):
    """An RGB-D frame: depth in metres (NaN: no reading), intrinsics, camera in the world."""

    @property
    def rgb(self) -> np.ndarray: ...

    @property
    def depth(self) -> np.ndarray: ...

    @property
    def K(self) -> np.ndarray: ...

    @property
    def T_world_camera(self) -> Pose: ...

    @property
    def stamp(self) -> float: ...


@dataclass
class Cluster:
    """Points of one object candidate, in the table frame.

    Attributes:
        points: Nx3, thinned to the voxel grid.
        normals: Nx3 unit normals, facing the camera.
    """

    points: np.ndarray
    normals: np.ndarray

    @property
    def top(self) -> float:
        """Height of the cluster's top above the table (m), robust to a stray point."""
        return float(np.percentile(self.points[:, 2], 98))

    @property
    def center(self) -> np.ndarray:
        return self.points.mean(axis=0)


@dataclass
class SceneCloud:
    """A frame seen relative to the table.

    Attributes:
        T_world_table: 4x4 world <- table frame.
        T_camera_table: 4x4 camera (OpenCV) <- table frame.
        K: 3x3 intrinsics; depth: HxW metres (NaN: no reading).
        heights: HxW height of each pixel's point above the table (NaN: no reading).
        table_xy: HxWx2 table-frame x, y of each pixel's point.
        clusters: the object candidates.
    """

    T_world_table: np.ndarray
    T_camera_table: np.ndarray
    K: np.ndarray
    depth: np.ndarray
    heights: np.ndarray
    table_xy: np.ndarray
    clusters: list[Cluster] = field(default_factory=list)

    @property
    def camera_in_table(self) -> np.ndarray:
        return np.linalg.inv(self.T_camera_table)[:3, 3]


def _world_grid(frame: FrameLike) -> np.ndarray:
    """HxWx3 world points of every pixel (NaN where the depth is missing)."""
    h, w = frame.depth.shape
    z = frame.depth.astype(np.float64)
    z[~(z > 0)] = np.nan
    k = frame.K
    u = (np.arange(w) - k[0, 2]) / k[0, 0]
    v = (np.arange(h) - k[1, 2]) / k[1, 1]
    cam = np.stack((u[None, :] * z, v[:, None] * z, z), axis=-1)
    t = pose_to_matrix(frame.T_world_camera)
    return cam @ t[:3, :3].T + t[:3, 3]


def _fit_table(points: np.ndarray, config: RecognitionConfig) -> np.ndarray:
    """(a, b, c, d) of the table: the largest near-horizontal plane, normal up."""
    rng = np.random.default_rng(0)  # deterministic: the same frame gives the same plane
    if len(points) > _PLANE_SAMPLE:
        points = points[rng.choice(len(points), _PLANE_SAMPLE, replace=False)]
    o3d.utility.random.seed(0)
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    for _ in range(3):  # a wall or a box side may be larger than the visible table
        if len(cloud.points) < 100:
            break
        plane, inliers = cloud.segment_plane(config.plane_threshold, 3, 200)
        normal = np.asarray(plane[:3])
        if abs(normal[2]) > 0.9:
            plane = np.sign(normal[2]) * np.asarray(plane)
            pts = np.asarray(cloud.points)
            # refit on the points well inside the band: a thin plate's top lies within it
            near = np.abs(pts @ plane[:3] + plane[3]) < config.plane_threshold / 3
            return _refine_plane(pts[near] if near.sum() > 50 else pts[inliers], plane)
        cloud = cloud.select_by_index(inliers, invert=True)
    raise PerceptionError("no table plane in view (nothing flat and level in the workspace)")


def _refine_plane(inliers: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """Least-squares plane through the RANSAC inliers (RANSAC keeps a 3-point sample)."""
    centroid = inliers.mean(axis=0)
    _, _, vt = np.linalg.svd(inliers - centroid, full_matrices=False)
    normal = vt[2] if vt[2][2] > 0 else -vt[2]
    if np.dot(normal, plane[:3]) < 0.99:
        normal = np.asarray(plane[:3]) / np.linalg.norm(plane[:3])
    return np.append(normal, -float(np.dot(normal, centroid)))


def _clusters(points: np.ndarray, camera: np.ndarray, config: RecognitionConfig) -> list[Cluster]:
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    cloud = cloud.voxel_down_sample(config.voxel)
    if len(cloud.points) == 0:
        return []
    labels = np.asarray(cloud.cluster_dbscan(config.cluster_eps, 4))
    found = []
    for label in range(int(labels.max()) + 1 if len(labels) else 0):
        part = cloud.select_by_index(np.nonzero(labels == label)[0].tolist())
        if len(part.points) < config.min_cluster_points:
            continue
        part.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(_NORMAL_NEIGHBOURS))
        part.orient_normals_towards_camera_location(camera)
        found.append(Cluster(np.asarray(part.points), np.asarray(part.normals)))
    return found


def segment_scene(frame: FrameLike, config: RecognitionConfig) -> SceneCloud:
    """The table and the object clusters on it; raise PerceptionError without a table."""
    grid = _world_grid(frame)
    lo, hi = np.asarray(config.workspace_min), np.asarray(config.workspace_max)
    inside = np.all((grid >= lo) & (grid <= hi), axis=-1)  # NaN compares False
    step = config.stride if frame.depth.shape[1] > 400 else 1
    sampled = inside[::step, ::step]
    points = grid[::step, ::step][sampled]
    if len(points) < 100:
        raise PerceptionError("the camera sees (almost) nothing of the workspace")
    t_world_table = table_frame(_fit_table(points, config))
    t_table_world = np.linalg.inv(t_world_table)
    local = grid @ t_table_world[:3, :3].T + t_table_world[:3, 3]
    heights = np.where(inside, local[..., 2], np.nan)
    above = (heights > config.min_height) & (heights < config.max_height)
    t_camera_table = np.linalg.inv(pose_to_matrix(frame.T_world_camera)) @ t_world_table
    scene = SceneCloud(t_world_table, t_camera_table, frame.K, frame.depth, heights, local[..., :2])
    camera = scene.camera_in_table
    scene.clusters = _clusters(local[::step, ::step][above[::step, ::step]], camera, config)
    return scene
