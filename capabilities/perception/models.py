"""Point models of the object library: points sampled on each mesh, with normals, a
nearest-neighbour index and FPFH features, built once per model and shared by threads.
"""

from __future__ import annotations

import functools
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from capabilities.object_library import ObjectLibrary, ObjectLibraryError, ObjectModelSpec
from capabilities.open3d_lib import o3d
from capabilities.perception.errors import PerceptionError

__all__ = ["ModelCloud", "ModelSet"]

_SPACING = 0.004  # m between sampled points
_MIN_POINTS, _MAX_POINTS = 1500, 8000


@dataclass
class ModelCloud:
    """One library model as points in its own frame (bottom centre, z up).

    Attributes:
        spec: the library entry.
        points, normals: Nx3 samples of the mesh surface and their outward normals.
        features: FPFH features of ``down`` (Open3D Feature), for global registration.
        down: the samples thinned to the matching voxel (Open3D PointCloud).
    """

    spec: ObjectModelSpec
    points: np.ndarray
    normals: np.ndarray
    down: Any
    features: Any
    _index: Any

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def height(self) -> float:
        return float(self.spec.dimensions[2])

    @property
    def holes(self) -> list[dict[str, Any]]:
        """The plate holes of the model (``extra["holes"]``), empty for other models."""
        holes = self.spec.extra.get("holes", [])
        return holes if isinstance(holes, list) else []

    def nearest(self, query: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(index, squared distance) of the nearest model point of each query point."""
        idx, dist2 = self._index.knn_search(_tensor(query), 1)
        return idx.numpy()[:, 0].astype(np.int64), dist2.numpy()[:, 0].astype(np.float64)


def fpfh(cloud: Any, voxel: float) -> Any:
    """FPFH features of a cloud that has normals (radius five voxels)."""
    search = o3d.geometry.KDTreeSearchParamHybrid(radius=5 * voxel, max_nn=100)
    return o3d.pipelines.registration.compute_fpfh_feature(cloud, search)  # type: ignore[call-arg]  # open3d stubs list only keyword arguments


def _tensor(array: np.ndarray) -> Any:
    """An Open3D tensor sharing a C-contiguous float64 copy of ``array``."""
    return o3d.core.Tensor(np.ascontiguousarray(array, dtype=np.float64))  # type: ignore[call-overload]  # open3d stubs lack the ndarray overload


def _load(spec: ObjectModelSpec, voxel: float) -> ModelCloud:
    mesh_file = Path(spec.mesh_file)
    try:
        stat = mesh_file.stat()
    except OSError as exc:
        raise PerceptionError(f"{mesh_file}: cannot read the mesh: {exc}") from exc
    return ModelCloud(spec, *_sampled(str(mesh_file), stat.st_mtime_ns, stat.st_size, voxel))


@functools.lru_cache(maxsize=64)
def _sampled(
    mesh_file: str, mtime_ns: int, size: int, voxel: float
) -> tuple[np.ndarray, np.ndarray, Any, Any, Any]:
    """Points, normals, thinned cloud, features and index of a mesh file as it is now.

    Kept for the process (by the file's path, time and size): every cell a process opens
    (a test, a reset of the cell, a benchmark's trials) recognises with the same models, and
    sampling them and their features took a second a cell. They are only read once built.
    """
    del mtime_ns, size  # part of the key only: a changed file is sampled again
    mesh = o3d.io.read_triangle_mesh(mesh_file)  # type: ignore[arg-type]  # open3d stubs want os.PathLike; str works
    if len(mesh.triangles) == 0:
        raise PerceptionError(f"{mesh_file}: no triangles to sample")
    mesh.compute_triangle_normals()
    count = int(np.clip(mesh.get_surface_area() / _SPACING**2, _MIN_POINTS, _MAX_POINTS))
    o3d.utility.random.seed(0)  # the same samples every time: recognition is reproducible
    cloud = mesh.sample_points_uniformly(count, use_triangle_normal=True)
    points = np.asarray(cloud.points).copy()
    points.flags.writeable = False
    normals = np.asarray(cloud.normals).copy()
    normals.flags.writeable = False
    down = cloud.voxel_down_sample(voxel)
    index = o3d.core.nns.NearestNeighborSearch(_tensor(points))
    index.knn_index()
    return points, normals, down, fpfh(down, voxel), index


class ModelSet:
    """The point models of a library, loaded on first use; safe to share between threads.

    Args:
        library: the object library.
        voxel: the grid (m) scene clusters are thinned to (features are made at that scale).
    """

    def __init__(self, library: ObjectLibrary, voxel: float) -> None:
        self._library = library
        self._voxel = voxel
        self._models: dict[str, ModelCloud] = {}
        self._lock = threading.Lock()

    @property
    def library(self) -> ObjectLibrary:
        return self._library

    def get(self, name: str) -> ModelCloud:
        with self._lock:
            if name not in self._models:
                try:
                    spec = self._library.get(name)
                except ObjectLibraryError as exc:
                    raise PerceptionError(str(exc)) from exc
                self._models[name] = _load(spec, self._voxel)
            return self._models[name]

    def all(self) -> list[ModelCloud]:
        """Every model of the library."""
        return [self.get(name) for name in self._library.names()]
