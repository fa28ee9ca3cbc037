"""ArUco marker detection and single-marker pose estimation in a camera image.

Markers are DICT_4X4_50. The marker frame has its origin at the marker centre, z out of the
printed face, x toward the texture's right and y toward its top (the OpenCV ArUco
convention). The side length includes the black border. Poses are returned in the OpenCV
camera frame (x right, y down, z forward).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from capabilities.markers.corners import refine_corners
from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import (
    marker_object_points,
    pose_from_rvec_tvec,
    rotvec_to_matrix,
)
from engine.types import Pose

__all__ = [
    "ARUCO_DICTIONARY",
    "MarkerObservation",
    "detect_markers",
    "marker_pose_world",
    "object_pose_from_marker",
    "check_camera",
]

ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50
# Two IPPE solutions whose RMS reprojection errors are within this ratio (plus a small
# floor for near-perfect fits) cannot be told apart by the image; a prior decides.
# A fixed pixel margin is wrong here: with good corners the right solution fits to 0.01 px
# and the mirrored one to 0.08 px, which must count as clearly different.
AMBIGUITY_RATIO = 1.5
AMBIGUITY_FLOOR_PX = 0.01
# Images up to this size (longest side, px) are searched at twice the resolution too: a 4 cm
# marker at 0.9 m is only ~12 px wide at 320x240, with 2 px cells the decoder can miss. The
# upscaled search misses others the plain one decodes (a cup's 3 cm top marker at a slant,
# 14 px wide at 640x480): both are searched, a marker found by either is kept.
_UPSCALE_BELOW_PX = 800


@dataclass(frozen=True)
class MarkerObservation:
    """One marker found in an image.

    Attributes:
        marker_id: the id in DICT_4X4_50.
        corners: (4, 2) float64 pixel corners, in the order top-left, top-right,
            bottom-right, bottom-left of the marker texture.
        pose: the marker frame in the camera frame (T_camera_marker).
        length: the side length used for the pose (m).
        reprojection_error: RMS distance (px) of the 4 corners from the reprojected model.
        confidence: 0..1; the detector's bit confidence, lowered for a large reprojection
            error and for an ambiguous (nearly fronto-parallel or tiny) marker.
        ambiguity: ratio of the best to the second IPPE solution's reprojection error
            (near 1: the image cannot tell the two tilts apart).
    """

    marker_id: int
    corners: NDArray[np.float64]
    pose: Pose
    length: float
    reprojection_error: float
    confidence: float
    ambiguity: float


def check_camera(
    k: NDArray[np.floating], dist: NDArray[np.floating] | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate a camera matrix and distortion vector; return them as float64 arrays.

    Raises:
        MarkerError: when K is not a finite 3x3 with positive focal lengths, or dist
            does not have 4, 5, 8, 12 or 14 finite coefficients.
    """
    try:
        kk = np.asarray(k, dtype=np.float64)
        dd = np.zeros(5) if dist is None else np.asarray(dist, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise MarkerError(f"camera matrix and distortion must be numeric arrays: {exc}") from exc
    if kk.shape != (3, 3) or not np.all(np.isfinite(kk)) or kk[0, 0] <= 0 or kk[1, 1] <= 0:
        raise MarkerError(f"K must be a finite 3x3 matrix with positive fx, fy; got {kk!r}")
    if dd.size not in (4, 5, 8, 12, 14) or not np.all(np.isfinite(dd)):
        raise MarkerError(f"dist must have 4, 5, 8, 12 or 14 finite coefficients; got {dd!r}")
    return kk, dd


def _grey(rgb: NDArray[np.generic]) -> NDArray[np.uint8]:
    if not isinstance(rgb, np.ndarray):
        raise MarkerError(f"image must be a numpy array, got {type(rgb).__name__}")
    if rgb.dtype != np.uint8:
        raise MarkerError(f"image must be uint8, got {rgb.dtype}")
    if rgb.ndim == 2:
        grey = rgb
    elif rgb.ndim == 3 and rgb.shape[2] == 3:
        grey = np.asarray(cv2.cvtColor(np.asarray(rgb, np.uint8), cv2.COLOR_RGB2GRAY), np.uint8)
    else:
        raise MarkerError(f"image must be HxWx3 (RGB) or HxW, got shape {rgb.shape}")
    if grey.shape[0] < 8 or grey.shape[1] < 8:
        raise MarkerError(f"image is too small: {rgb.shape}")
    return np.ascontiguousarray(grey)


def _positive_length(value: object) -> bool:
    return (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and math.isfinite(value)
        and value > 0
    )


def _lengths(marker_lengths: Mapping[int, float] | float) -> Mapping[int, float] | float:
    bad: dict[object, object]
    if isinstance(marker_lengths, Mapping):
        bad = {i: v for i, v in marker_lengths.items() if not _positive_length(v)}
    elif isinstance(marker_lengths, (int, float)) and not isinstance(marker_lengths, bool):
        bad = {} if _positive_length(marker_lengths) else {"all": marker_lengths}
    else:
        raise MarkerError(
            f"marker_lengths must be a number or a mapping id -> m, got {marker_lengths!r}"
        )
    if bad:
        raise MarkerError(f"marker lengths must be positive and finite (m), got {bad}")
    return marker_lengths


def _detector() -> cv2.aruco.ArucoDetector:
    params = cv2.aruco.DetectorParameters()
    # The detector's corners only seed refine_corners (edge fitting), which is far more
    # accurate on small markers than CORNER_REFINE_SUBPIX; see corners.py.
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_NONE
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY), params)


def _find(grey: NDArray[np.uint8]) -> list[tuple[int, NDArray[np.float64], float]]:
    """(id, refined 4x2 corners, detector confidence) of every marker in a grey image."""
    scales = (2, 1) if max(grey.shape) <= _UPSCALE_BELOW_PX else (1,)
    found: list[tuple[int, NDArray[np.float64], float]] = []
    for scale in scales:
        known = {marker_id for marker_id, _, _ in found}
        found += [hit for hit in _search(grey, scale) if hit[0] not in known]
    return found


def _search(grey: NDArray[np.uint8], scale: int) -> list[tuple[int, NDArray[np.float64], float]]:
    """The markers the detector decodes in ``grey`` resized by ``scale``, refined at 1:1."""
    search = grey if scale == 1 else cv2.resize(grey, None, fx=scale, fy=scale)
    corners_list, ids, confidences, _ = _detector().detectMarkersWithConfidence(search)
    if ids is None or len(ids) == 0:
        return []
    found = []
    for corners, marker_id, conf in zip(
        corners_list, ids.reshape(-1), np.asarray(confidences).reshape(-1), strict=True
    ):
        # Pixel centres are integers at both scales: u = (U + 0.5) / scale - 0.5.
        seed = (np.asarray(corners, dtype=np.float64).reshape(4, 2) + 0.5) / scale - 0.5
        refined, _ = refine_corners(grey, seed)
        found.append((int(marker_id), refined, float(conf)))
    return found


def _rms(
    obj: NDArray[np.float64],
    img: NDArray[np.float64],
    rvec: NDArray[np.float64],
    tvec: NDArray[np.float64],
    k: NDArray[np.float64],
    dist: NDArray[np.float64],
) -> float:
    proj, _ = cv2.projectPoints(obj, rvec, tvec, k, dist)
    return float(np.sqrt(np.mean(np.sum((proj.reshape(-1, 2) - img) ** 2, axis=1))))


def _frontality(rvec: NDArray[np.float64], tvec: NDArray[np.float64]) -> float:
    """Cosine between the marker normal and the direction from the marker to the camera."""
    normal = rotvec_to_matrix(rvec)[:, 2]
    to_camera = -tvec.reshape(3) / max(float(np.linalg.norm(tvec)), 1e-12)
    return float(normal @ to_camera)


def _solve_marker(
    corners: NDArray[np.float64], length: float, k: NDArray[np.float64], dist: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float] | None:
    """IPPE-square pose of one marker: (rvec, tvec, rms px, ambiguity), or None."""
    obj = marker_object_points(length)
    ok, rvecs, tvecs, _ = cv2.solvePnPGeneric(obj, corners, k, dist, flags=cv2.SOLVEPNP_IPPE_SQUARE)
    if not ok or len(rvecs) == 0:
        return None
    candidates = []
    for rvec, tvec in zip(rvecs, tvecs, strict=True):
        refined = cv2.solvePnPRefineLM(obj, corners, k, dist, rvec.copy(), tvec.copy())
        rvec, tvec = (np.asarray(v, dtype=np.float64) for v in refined)
        if float(tvec[2, 0]) <= 0 or _frontality(rvec, tvec) <= 0:
            continue  # behind the camera or showing its back: not what was seen
        candidates.append((_rms(obj, corners, rvec, tvec, k, dist), rvec, tvec))
    if not candidates:
        return None
    candidates.sort(key=lambda c: c[0])
    best = candidates[0]
    ambiguity = 1.0
    if len(candidates) > 1:
        second = candidates[1]
        ambiguity = best[0] / max(second[0], 1e-12)
        close = second[0] <= AMBIGUITY_RATIO * best[0] + AMBIGUITY_FLOOR_PX
        if close and _frontality(second[1], second[2]) > _frontality(best[1], best[2]):
            best = second
    return best[1], best[2], best[0], ambiguity


def _confidence(detector_confidence: float, rms: float, ambiguity: float) -> float:
    # Reprojection: ~1 below 0.3 px, 0.5 at 1 px. Ambiguity: an IPPE pair that fits
    # equally well (ratio -> 1) halves the confidence, since the tilt may be mirrored.
    fit = 1.0 / (1.0 + rms * rms)
    ambiguous = 1.0 - 0.5 * ambiguity**4
    return float(np.clip(detector_confidence * fit * ambiguous, 0.0, 1.0))


def detect_markers(
    rgb: NDArray[np.generic],
    k: NDArray[np.floating],
    marker_lengths: Mapping[int, float] | float,
    dist: NDArray[np.floating] | None = None,
) -> list[MarkerObservation]:
    """Find DICT_4X4_50 markers in an image and estimate each one's pose in the camera frame.

    Corners are refined to sub-pixel accuracy; each pose comes from IPPE (square) refined
    by Levenberg-Marquardt. Of the two IPPE solutions, the one with the lower reprojection
    error wins; when they are within ``AMBIGUITY_RATIO`` the one whose face looks more
    directly at the camera wins. Solutions behind the camera or showing their back are
    discarded.

    Args:
        rgb: HxWx3 uint8 RGB image (HxW grey is accepted too).
        k: 3x3 camera matrix of the image.
        marker_lengths: side length (m, black border included) for every marker, or a
            mapping id -> length; markers whose id is not in the mapping are left out.
        dist: OpenCV distortion coefficients, None for an undistorted image.

    Returns:
        The observations, sorted by marker id (an empty list when none is seen).

    Raises:
        MarkerError: on an image that is not uint8 HxWx3/HxW, a bad K or dist, or a
            non-positive length.
    """
    grey = _grey(rgb)
    kk, dd = check_camera(k, dist)
    lengths = _lengths(marker_lengths)
    found = []
    for mid, image_points, det_conf in _find(grey):
        length = lengths.get(mid) if isinstance(lengths, Mapping) else lengths
        if length is None:
            continue
        solution = _solve_marker(image_points, float(length), kk, dd)
        if solution is None:
            continue
        rvec, tvec, rms, ambiguity = solution
        found.append(
            MarkerObservation(
                marker_id=mid,
                corners=image_points,
                pose=pose_from_rvec_tvec(rvec, tvec),
                length=float(length),
                reprojection_error=rms,
                confidence=_confidence(det_conf, rms, ambiguity),
                ambiguity=ambiguity,
            )
        )
    return sorted(found, key=lambda o: o.marker_id)


def marker_pose_world(observation: MarkerObservation, t_world_camera: Pose) -> Pose:
    """The observed marker's pose in the world, given the camera's pose in the world."""
    return t_world_camera.compose(observation.pose)


def object_pose_from_marker(marker_pose_world: Pose, marker_in_object: Pose) -> Pose:
    """An object's pose in the world from its marker's world pose.

    Args:
        marker_pose_world: T_world_marker, e.g. from :func:`marker_pose_world`.
        marker_in_object: T_object_marker, where the marker sits on the object.

    Returns:
        T_world_object = T_world_marker * T_object_marker^-1.
    """
    return marker_pose_world.compose(marker_in_object.inverse())
