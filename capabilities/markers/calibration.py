"""Camera extrinsic calibration from markers whose poses in the world are known.

All corners of all known markers seen in one or more images are used in one joint PnP, so
several markers spread over the view constrain the camera far better than one. Robustness
to a marker whose known pose is wrong (moved, mis-measured) comes from hypothesise-and-
verify: each single marker (its IPPE pose) and each pair of markers (joint PnP) proposes a
camera pose, every proposal is scored by how many markers it reprojects within
``outlier_px``, and the best one is refined by Levenberg-Marquardt on its inlier markers.

Two cases: a static camera (:func:`calibrate_extrinsics`, gives T_world_camera) and a camera
on the wrist (:func:`calibrate_eye_in_hand`, gives T_tool_camera from images taken at known
tool poses); both reduce to the same problem, the camera pose in a "rig" frame in which the
marker corners are known for each image.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from capabilities.markers.detection import MarkerObservation, check_camera
from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import (
    marker_object_points,
    matrix_to_pose,
    pose_to_matrix,
    pose_to_rvec_tvec,
    rotvec_to_matrix,
    transform_points,
)
from engine.types import Pose

__all__ = ["CalibrationReport", "calibrate_extrinsics", "calibrate_eye_in_hand"]

_MAX_PAIRS = 200  # pair hypotheses tried at most; enough for ~20 marker sightings
_REFINE_ROUNDS = 5

Array = NDArray[np.float64]


@dataclass(frozen=True)
class CalibrationReport:
    """How well the calibrated camera explains the marker corners.

    Attributes:
        rms_px: RMS reprojection error (px) over all corners of the inlier markers.
        per_marker_rms_px: RMS error (px) of each known marker seen, inliers and outliers.
        inliers: ids of the markers used for the final pose.
        outliers: ids of known markers rejected (error above ``outlier_px``).
        ignored: ids seen that have no known pose.
        points: number of corners in the final fit.
        images: number of images given.
    """

    rms_px: float
    per_marker_rms_px: Mapping[int, float]
    inliers: tuple[int, ...]
    outliers: tuple[int, ...]
    ignored: tuple[int, ...]
    points: int
    images: int


@dataclass(frozen=True)
class _Sighting:
    """One marker in one image: its corners in the rig frame and in the image."""

    marker_id: int
    rig_points: Array  # (4, 3)
    image_points: Array  # (4, 2)
    t_camera_marker: Array  # 4x4, the detection's own pose
    t_rig_marker: Array  # 4x4


def _sightings(
    images: Sequence[Sequence[MarkerObservation]],
    t_rig_world: Sequence[Array],
    known_markers: Mapping[int, Pose],
) -> tuple[list[_Sighting], tuple[int, ...]]:
    sightings, ignored = [], set()
    for observations, rig_world in zip(images, t_rig_world, strict=True):
        for obs in observations:
            if obs.marker_id not in known_markers:
                ignored.add(obs.marker_id)
                continue
            t_rig_marker = rig_world @ pose_to_matrix(known_markers[obs.marker_id])
            sightings.append(
                _Sighting(
                    marker_id=obs.marker_id,
                    rig_points=transform_points(t_rig_marker, marker_object_points(obs.length)),
                    image_points=np.asarray(obs.corners, dtype=np.float64).reshape(4, 2),
                    t_camera_marker=pose_to_matrix(obs.pose),
                    t_rig_marker=t_rig_marker,
                )
            )
    return sightings, tuple(sorted(ignored))


def _stack(sightings: Sequence[_Sighting]) -> tuple[Array, Array]:
    obj = np.concatenate([s.rig_points for s in sightings])
    img = np.concatenate([s.image_points for s in sightings])
    return obj, img


def _marker_rms(
    sightings: Sequence[_Sighting], rvec: Array, tvec: Array, k: Array, dist: Array
) -> dict[int, float]:
    """RMS reprojection error per marker id; inf for a marker behind the camera."""
    r = rotvec_to_matrix(rvec)
    squared: dict[int, list[float]] = {}
    for s in sightings:
        depth = (s.rig_points @ r.T + tvec.reshape(3))[:, 2]
        if np.any(depth <= 0):
            squared.setdefault(s.marker_id, []).append(math.inf)
            continue
        proj, _ = cv2.projectPoints(s.rig_points, rvec, tvec, k, dist)
        err = np.sum((proj.reshape(-1, 2) - s.image_points) ** 2, axis=1)
        squared.setdefault(s.marker_id, []).extend(float(e) for e in err)
    return {mid: math.sqrt(float(np.mean(v))) for mid, v in squared.items()}


def _hypotheses(sightings: Sequence[_Sighting], k: Array, dist: Array) -> list[tuple[Array, Array]]:
    """Candidate (rvec, tvec) of T_camera_rig from single markers and pairs of markers."""
    out = []
    for s in sightings:
        t_camera_rig = s.t_camera_marker @ np.linalg.inv(s.t_rig_marker)
        out.append(pose_to_rvec_tvec(matrix_to_pose(t_camera_rig)))
    pairs = [(a, b) for a, b in itertools.combinations(sightings, 2) if a.marker_id != b.marker_id]
    for a, b in pairs[:_MAX_PAIRS]:
        obj, img = _stack((a, b))
        ok, rvec, tvec = cv2.solvePnP(obj, img, k, dist, flags=cv2.SOLVEPNP_SQPNP)
        if ok:
            out.append(
                (np.asarray(rvec, np.float64).reshape(3), np.asarray(tvec, np.float64).reshape(3))
            )
    return out


def _score(rms: Mapping[int, float], outlier_px: float) -> tuple[int, float]:
    inlier_errors = [e for e in rms.values() if e <= outlier_px]
    return len(inlier_errors), -float(sum(e * e for e in inlier_errors))


def _refine(
    sightings: Sequence[_Sighting],
    start: tuple[Array, Array],
    k: Array,
    dist: Array,
    outlier_px: float,
) -> tuple[Array, Array, dict[int, float], set[int]]:
    """LM refinement on the inlier markers, re-deciding inliers until they settle."""
    rvec, tvec = (np.asarray(v, dtype=np.float64).reshape(3, 1).copy() for v in start)
    rms = _marker_rms(sightings, rvec, tvec, k, dist)
    inliers = {mid for mid, e in rms.items() if e <= outlier_px}
    for _ in range(_REFINE_ROUNDS):
        obj, img = _stack([s for s in sightings if s.marker_id in inliers])
        refined = cv2.solvePnPRefineLM(obj, img, k, dist, rvec, tvec)
        rvec, tvec = (np.asarray(v, dtype=np.float64) for v in refined)
        rms = _marker_rms(sightings, rvec, tvec, k, dist)
        settled = {mid for mid, e in rms.items() if e <= outlier_px}
        if settled == inliers or not settled:
            break
        inliers = settled
    return rvec, tvec, rms, inliers


def _solve(
    sightings: Sequence[_Sighting],
    k: Array,
    dist: Array,
    outlier_px: float,
) -> tuple[Array, dict[int, float], set[int], float, int]:
    """T_camera_rig (4x4), per-marker rms, inliers, inlier rms, inlier point count."""
    candidates = _hypotheses(sightings, k, dist)
    scored = [
        (_score(_marker_rms(sightings, r, t, k, dist), outlier_px), i)
        for i, (r, t) in enumerate(candidates)
    ]
    (count, _), best = max(scored)
    if count == 0:
        raise MarkerError(
            f"no camera pose explains any known marker within {outlier_px} px; "
            "check the intrinsics, the marker lengths and the known marker poses"
        )
    rvec, tvec, rms, inliers = _refine(sightings, candidates[best], k, dist, outlier_px)
    used = [s for s in sightings if s.marker_id in inliers]
    obj, img = _stack(used)
    proj, _ = cv2.projectPoints(obj, rvec, tvec, k, dist)
    total = math.sqrt(float(np.mean(np.sum((proj.reshape(-1, 2) - img) ** 2, axis=1))))
    t_camera_rig = np.eye(4)
    t_camera_rig[:3, :3] = rotvec_to_matrix(rvec)
    t_camera_rig[:3, 3] = tvec.reshape(3)
    return t_camera_rig, rms, inliers, total, len(obj)


def _calibrate(
    images: Sequence[Sequence[MarkerObservation]],
    t_rig_world: Sequence[Array],
    known_markers: Mapping[int, Pose],
    k: NDArray[np.floating],
    dist: NDArray[np.floating] | None,
    outlier_px: float,
) -> tuple[Pose, CalibrationReport]:
    kk, dd = check_camera(k, dist)
    if not outlier_px > 0:
        raise MarkerError(f"outlier_px must be positive, got {outlier_px}")
    sightings, ignored = _sightings(images, t_rig_world, known_markers)
    if not sightings:
        raise MarkerError(f"no marker with a known pose was seen (seen without a pose: {ignored})")
    t_camera_rig, rms, inliers, total, points = _solve(sightings, kk, dd, outlier_px)
    report = CalibrationReport(
        rms_px=total,
        per_marker_rms_px=dict(sorted(rms.items())),
        inliers=tuple(sorted(inliers)),
        outliers=tuple(sorted(set(rms) - inliers)),
        ignored=ignored,
        points=points,
        images=len(images),
    )
    return matrix_to_pose(np.linalg.inv(t_camera_rig)), report


def calibrate_extrinsics(
    images: Sequence[Sequence[MarkerObservation]],
    known_markers: Mapping[int, Pose],
    k: NDArray[np.floating],
    dist: NDArray[np.floating] | None = None,
    *,
    outlier_px: float = 3.0,
) -> tuple[Pose, CalibrationReport]:
    """The pose of a static camera in the world from markers of known world pose.

    Args:
        images: for each image taken by the camera (it must not move between them), the
            observations from :func:`detect_markers`; each observation's ``length`` is
            used for its corners.
        known_markers: marker id -> T_world_marker. Markers not listed are ignored.
        k: 3x3 camera matrix.
        dist: distortion coefficients (None: none).
        outlier_px: a marker whose corners reproject worse than this (RMS px) is an
            outlier and does not take part in the final fit.

    Returns:
        T_world_camera (OpenCV camera frame) and a :class:`CalibrationReport`.

    Raises:
        MarkerError: when no known marker is seen, or no pose fits any of them.
    """
    identity = [np.eye(4, dtype=np.float64)] * len(images)
    return _calibrate(images, identity, known_markers, k, dist, outlier_px)


def calibrate_eye_in_hand(
    images: Sequence[Sequence[MarkerObservation]],
    tool_poses: Sequence[Pose],
    known_markers: Mapping[int, Pose],
    k: NDArray[np.floating],
    dist: NDArray[np.floating] | None = None,
    *,
    outlier_px: float = 3.0,
) -> tuple[Pose, CalibrationReport]:
    """The pose of a wrist camera on the tool from markers of known world pose.

    Each image is taken at a known tool pose; the markers' corners are expressed in that
    image's tool frame, where the camera is fixed, and one joint PnP gives T_camera_tool.
    Use several tool poses that look at the markers from different directions.

    Args:
        images: per image, the observations from :func:`detect_markers`.
        tool_poses: per image, T_world_tool from the robot's kinematics.
        known_markers: marker id -> T_world_marker.
        k: 3x3 camera matrix.
        dist: distortion coefficients (None: none).
        outlier_px: see :func:`calibrate_extrinsics`.

    Returns:
        T_tool_camera and a :class:`CalibrationReport`.

    Raises:
        MarkerError: on a count mismatch, when no known marker is seen, or nothing fits.
    """
    if len(tool_poses) != len(images):
        raise MarkerError(f"{len(images)} images but {len(tool_poses)} tool poses")
    t_tool_world = [pose_to_matrix(p.inverse()) for p in tool_poses]
    return _calibrate(images, t_tool_world, known_markers, k, dist, outlier_px)
