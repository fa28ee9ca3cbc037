"""Matching a cluster to a model: hypotheses, planar ICP, and a score that can say no.

An object resting on the table has three unknowns in the table frame: x, y and yaw.
Hypotheses come from the cluster's footprint (the centre and sides of its minimum-area
rectangle) and, for shapes with distinctive geometry, from FPFH features matched by RANSAC
(Open3D global registration). Each is refined by ICP restricted to (x, y, yaw), minimising
point-to-plane distances from the scene to the model surface with a small point-to-point
term (it keeps flat faces from sliding). A fit is scored on both sides:

- fitness: the share of scene points within ``inlier_distance`` of the model surface;
- consistency: the share of the model's camera-facing surface that the depth image does not
  contradict (a model surface where the camera saw through to something farther away is
  wrong). This rejects a model larger than the object, which fitness alone cannot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from capabilities.open3d_lib import o3d
from capabilities.perception.config import RecognitionConfig
from capabilities.perception.geometry import upright_matrix, yaw_of
from capabilities.perception.models import ModelCloud, fpfh
from capabilities.perception.scene_cloud import Cluster, SceneCloud

__all__ = ["Fit", "best_fit", "free_space_consistency", "planar_icp"]

_COARSE, _FINE = 0.03, 0.012  # m: correspondence gates of the first and last ICP rounds
_POINT_WEIGHT = 0.3  # weight of the point-to-point rows next to the point-to-plane ones
_CHECK_POINTS = 1500
# ICP fits three unknowns: a few hundred points pin them as well as thousands do, and a kit
# bin's cluster (3,300 points, 4 hypotheses, 2 models) took a second a look on every point.
_ICP_POINTS = 600
_GOOD_SCORE = 0.85  # a footprint fit this good needs no global registration
_RANSAC_SEED = 0


@dataclass(frozen=True)
class Fit:
    """A model placed on a cluster: pose in the table frame and how well it explains it."""

    model: str
    x: float
    y: float
    yaw: float
    fitness: float
    rmse: float
    consistency: float

    @property
    def score(self) -> float:
        return self.fitness * self.consistency


def _to_model(points: np.ndarray, x: float, y: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = points[:, 0] - x, points[:, 1] - y
    return np.column_stack((c * dx + s * dy, -s * dx + c * dy, points[:, 2]))


def _icp_step(
    p: np.ndarray, q: np.ndarray, n: np.ndarray, rotate: bool
) -> tuple[float, float, float]:
    """Least-squares (d_yaw, dx, dy) moving scene points ``p`` (model frame) onto the model."""
    lever = n[:, 0] * -p[:, 1] + n[:, 1] * p[:, 0]
    plane = np.column_stack((lever, n[:, 0], n[:, 1]))
    zeros, ones = np.zeros(len(p)), np.ones(len(p))
    px = np.column_stack((-p[:, 1], ones, zeros)) * _POINT_WEIGHT
    py = np.column_stack((p[:, 0], zeros, ones)) * _POINT_WEIGHT
    a = np.vstack((plane, px, py))
    diff = p - q
    b = -np.concatenate(
        ((n * diff).sum(axis=1), diff[:, 0] * _POINT_WEIGHT, diff[:, 1] * _POINT_WEIGHT)
    )
    if not rotate:
        sol = np.linalg.lstsq(a[:, 1:], b, rcond=None)[0]
        return 0.0, float(sol[0]), float(sol[1])
    sol = np.linalg.lstsq(a, b, rcond=None)[0]
    return float(sol[0]), float(sol[1]), float(sol[2])


def planar_icp(
    points: np.ndarray, model: ModelCloud, x: float, y: float, yaw: float, rotate: bool = True
) -> tuple[float, float, float]:
    """Refine (x, y, yaw) of ``model`` on scene ``points`` (table frame).

    Larger clouds are thinned to about ``_ICP_POINTS`` by a fixed stride (the same points
    every time: recognition stays reproducible); the fit is scored on all of them.
    """
    points = points[:: -(-len(points) // _ICP_POINTS)]
    for i in range(24):
        gate = _COARSE if i < 8 else _FINE
        p = _to_model(points, x, y, yaw)
        idx, dist2 = model.nearest(p)
        keep = dist2 < gate * gate
        if keep.sum() < 10:
            break
        d_yaw, dx, dy = _icp_step(
            p[keep], model.points[idx[keep]], model.normals[idx[keep]], rotate
        )
        # p' = R(d_yaw) p + d in the model frame: the pose becomes yaw - d_yaw, t - R(yaw') d
        yaw -= d_yaw
        c, s = math.cos(yaw), math.sin(yaw)
        x, y = x - (c * dx - s * dy), y - (s * dx + c * dy)
        if abs(d_yaw) < 1e-4 and math.hypot(dx, dy) < 5e-5 and i >= 8:
            break
    return x, y, yaw


def free_space_consistency(
    scene: SceneCloud, model: ModelCloud, pose: np.ndarray, tolerance: float
) -> float:
    """Share of the model's camera-facing surface (at ``pose``, table frame) not contradicted
    by the depth image: where the camera saw farther than the model surface, it is wrong.
    """
    step = max(1, len(model.points) // _CHECK_POINTS)
    pts = model.points[::step] @ pose[:3, :3].T + pose[:3, 3]
    nrm = model.normals[::step] @ pose[:3, :3].T
    facing = ((scene.camera_in_table - pts) * nrm).sum(axis=1) > 0
    cam = pts[facing] @ scene.T_camera_table[:3, :3].T + scene.T_camera_table[:3, 3]
    cam = cam[cam[:, 2] > 0.05]
    u = np.rint(scene.K[0, 0] * cam[:, 0] / cam[:, 2] + scene.K[0, 2]).astype(int)
    v = np.rint(scene.K[1, 1] * cam[:, 1] / cam[:, 2] + scene.K[1, 2]).astype(int)
    h, w = scene.depth.shape
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    if inside.sum() < 10:
        return 0.0
    seen = scene.depth[v[inside], u[inside]].astype(np.float64)
    expected = cam[inside, 2]
    wrong = ~np.isfinite(seen) | (seen > expected + tolerance)
    return float(1.0 - wrong.mean())


def _footprint_hypotheses(cluster: Cluster, model: ModelCloud) -> list[tuple[float, float, float]]:
    (cx, cy), _, angle = cv2.minAreaRect(cluster.points[:, :2].astype(np.float32))
    base = math.radians(angle)
    sym = model.spec.symmetry
    if sym.kind == "continuous":
        return [(cx, cy, 0.0)]
    turns = 4 if sym.kind == "none" or sym.order % 4 != 0 else 1
    turns = 2 if sym.kind == "discrete" and sym.order == 2 else turns
    return [(cx, cy, base + k * math.pi / 2) for k in range(turns)]


def _global_hypothesis(
    cluster: Cluster, model: ModelCloud, voxel: float
) -> tuple[float, float, float] | None:
    """FPFH + RANSAC: the model (features made at the same voxel) onto the cluster."""
    if len(cluster.points) < 30:
        return None
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(cluster.points))
    cloud.normals = o3d.utility.Vector3dVector(cluster.normals)
    reg = o3d.pipelines.registration
    # The same draws for the same clouds, whatever ran before in the process (Open3D's
    # generator is global): a run, a test and a benchmark's trial are reproducible.
    o3d.utility.random.seed(_RANSAC_SEED)
    result = reg.registration_ransac_based_on_feature_matching(
        model.down,
        cloud,
        model.features,
        fpfh(cloud, voxel),
        True,
        2.0 * voxel,
        reg.TransformationEstimationPointToPoint(False),
        3,
        [
            reg.CorrespondenceCheckerBasedOnEdgeLength(0.9),
            reg.CorrespondenceCheckerBasedOnDistance(2.0 * voxel),
        ],
        reg.RANSACConvergenceCriteria(20000, 0.99),
    )
    if result.fitness <= 0.0:
        return None
    t = np.asarray(result.transformation)
    return float(t[0, 3]), float(t[1, 3]), yaw_of(t[:3, :3])


def _score(
    scene: SceneCloud,
    cluster: Cluster,
    model: ModelCloud,
    hyp: tuple[float, float, float],
    config: RecognitionConfig,
) -> Fit:
    x, y, yaw = hyp
    _, dist2 = model.nearest(_to_model(cluster.points, x, y, yaw))
    inliers = dist2 < config.inlier_distance**2
    rmse = float(np.sqrt(dist2[inliers].mean())) if inliers.any() else math.inf
    consistency = free_space_consistency(
        scene, model, upright_matrix(x, y, yaw), config.free_space_tolerance
    )
    return Fit(model.name, x, y, yaw, float(inliers.mean()), rmse, consistency)


def best_fit(
    scene: SceneCloud, cluster: Cluster, models: list[ModelCloud], config: RecognitionConfig
) -> Fit:
    """The best placement of any of ``models`` (at least one) on ``cluster``, after ICP.

    Global registration costs more than the rest together, so it is tried only when no
    model's footprint hypotheses gave a good fit (an object half hidden, an odd outline):
    a cluster one model explains well is not registered against every other model the
    library holds.
    """
    fits = [
        _refine_best(scene, cluster, m, _footprint_hypotheses(cluster, m), config) for m in models
    ]
    if config.global_registration and max(f.score for f in fits) < _GOOD_SCORE:
        for i, model in enumerate(models):
            with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
                found = _global_hypothesis(cluster, model, config.voxel)
            if found is not None:
                other = _refine_best(scene, cluster, model, [found], config)
                fits[i] = other if other.score > fits[i].score else fits[i]
    return max(fits, key=lambda f: f.score)


def _refine_best(
    scene: SceneCloud,
    cluster: Cluster,
    model: ModelCloud,
    hypotheses: list[tuple[float, float, float]],
    config: RecognitionConfig,
) -> Fit:
    rotate = model.spec.symmetry.kind != "continuous"
    best: Fit | None = None
    for hyp in hypotheses:
        refined = planar_icp(cluster.points, model, *hyp, rotate=rotate)
        fit = _score(scene, cluster, model, refined, config)
        if best is None or (fit.score, -fit.rmse) > (best.score, -best.rmse):
            best = fit
    assert best is not None, "no hypothesis"
    return best
