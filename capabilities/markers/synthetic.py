"""A small OpenCV-only renderer of planar ArUco markers, for tests with exact ground truth.

Each marker is drawn as its texture (``cv2.aruco.generateImageMarker`` plus a white quiet
zone) warped by the homography that maps the texture onto the projection of the marker's
3D corners through a pinhole camera. The scene is rendered at ``supersample`` times the
resolution and reduced with area averaging, which anti-aliases the edges the way a real
sensor integrates light over a pixel. Pixel centres are at integer coordinates (OpenCV).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import (
    marker_object_points,
    matrix_to_pose,
    pose_to_matrix,
    transform_points,
)
from engine.types import Pose

__all__ = ["SyntheticMarker", "camera_matrix", "look_at", "project_points", "render_markers"]

ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50
_CELLS = 6  # a 4x4 marker is 4 data cells plus one black border cell on each side
_TEXTURE_CELL_PX = 32
_NEAR = 0.01  # m; markers with a corner closer than this to the camera plane are not drawn


@dataclass(frozen=True)
class SyntheticMarker:
    """A marker in the scene.

    Attributes:
        marker_id: id in DICT_4X4_50.
        pose: the marker frame in the world (centre, z out of the face, x right, y up).
        length: side of the black square in m (the white quiet zone is drawn around it).
    """

    marker_id: int
    pose: Pose
    length: float


def camera_matrix(width: int, height: int, hfov_deg: float = 60.0) -> NDArray[np.float64]:
    """A pinhole K with square pixels, the principal point at the image centre."""
    f = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
    return np.array([[f, 0.0, (width - 1) / 2.0], [0.0, f, (height - 1) / 2.0], [0.0, 0.0, 1.0]])


def look_at(
    eye: Sequence[float], target: Sequence[float], up: Sequence[float] = (0.0, 0.0, 1.0)
) -> Pose:
    """T_world_camera of a camera at ``eye`` looking at ``target``, OpenCV frame.

    The camera's y axis (image down) points as much as possible against ``up``.

    Raises:
        MarkerError: when eye and target coincide or the view is parallel to ``up``.
    """
    z = np.asarray(target, np.float64) - np.asarray(eye, np.float64)
    x = np.cross(z, np.asarray(up, np.float64))
    if np.linalg.norm(z) < 1e-9 or np.linalg.norm(x) < 1e-9 * max(1.0, float(np.linalg.norm(z))):
        raise MarkerError(f"cannot look from {eye} at {target} with up {up}")
    z, x = z / np.linalg.norm(z), x / np.linalg.norm(x)
    m = np.eye(4)
    m[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    m[:3, 3] = eye
    return matrix_to_pose(m)


def project_points(
    points_world: NDArray[np.floating], k: NDArray[np.floating], t_world_camera: Pose
) -> NDArray[np.float64]:
    """Project (N, 3) world points to (N, 2) pixels (no distortion)."""
    cam = transform_points(np.linalg.inv(pose_to_matrix(t_world_camera)), points_world)
    uvw = cam @ np.asarray(k, dtype=np.float64).T
    return np.asarray(uvw[:, :2] / uvw[:, 2:3], dtype=np.float64)


def _marker_texture(marker_id: int, quiet_cells: int) -> NDArray[np.uint8]:
    dictionary = cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY)
    side = _CELLS * _TEXTURE_CELL_PX
    marker = cv2.aruco.generateImageMarker(dictionary, marker_id, side)
    pad = quiet_cells * _TEXTURE_CELL_PX
    return np.asarray(
        cv2.copyMakeBorder(marker, pad, pad, pad, pad, cv2.BORDER_CONSTANT, value=255), np.uint8
    )


def _draw_marker(
    canvas: NDArray[np.float32],
    marker: SyntheticMarker,
    k_hi: NDArray[np.float64],
    t_camera_world: NDArray[np.float64],
    quiet_cells: int,
) -> None:
    """Paint one marker into the supersampled canvas (in place), if it faces the camera."""
    t_camera_marker = t_camera_world @ pose_to_matrix(marker.pose)
    normal, centre = t_camera_marker[:3, 2], t_camera_marker[:3, 3]
    if float(normal @ centre) >= 0.0:  # back face: the texture is printed on one side only
        return
    extent = marker.length * (_CELLS + 2 * quiet_cells) / _CELLS
    corners_cam = transform_points(t_camera_marker, marker_object_points(extent))
    if np.any(corners_cam[:, 2] < _NEAR):
        return
    uvw = corners_cam @ k_hi.T
    dst = (uvw[:, :2] / uvw[:, 2:3]).astype(np.float32)
    texture = _marker_texture(marker.marker_id, quiet_cells)
    s = texture.shape[0]
    # Texture pixel centres are integers, so its outer edges sit at -0.5 and s - 0.5.
    src = np.array([[-0.5, -0.5], [s - 0.5, -0.5], [s - 0.5, s - 0.5], [-0.5, s - 0.5]], np.float32)
    h = cv2.getPerspectiveTransform(src, dst)
    size = (canvas.shape[1], canvas.shape[0])
    warped = cv2.warpPerspective(texture.astype(np.float32), h, size, flags=cv2.INTER_LINEAR)
    mask = cv2.warpPerspective(np.ones(texture.shape, np.float32), h, size, flags=cv2.INTER_LINEAR)
    # The texture's own border fades against 0 in the warp; divide it out so the quiet
    # zone stays white up to the (partially covered) edge pixels.
    colour = np.divide(warped, mask, out=np.zeros_like(warped), where=mask > 1e-6)
    canvas *= 1.0 - mask
    canvas += mask * colour


def render_markers(
    markers: Sequence[SyntheticMarker],
    k: NDArray[np.floating],
    t_world_camera: Pose,
    size: tuple[int, int],
    *,
    background: float = 128.0,
    quiet_cells: int = 1,
    supersample: int = 4,
    blur_sigma: float = 0.0,
    noise_sigma: float = 0.0,
    seed: int = 0,
) -> NDArray[np.uint8]:
    """Render markers on a grey background as an RGB image.

    Args:
        markers: the markers to draw; nearer ones are painted over farther ones.
        k: 3x3 camera matrix of the output image.
        t_world_camera: camera pose in the world, OpenCV frame (x right, y down, z forward).
        size: (width, height) in pixels.
        background: grey level of the background, 0-255.
        quiet_cells: width of the white margin around each marker, in marker cells.
        supersample: integer oversampling factor for anti-aliasing (1 = none).
        blur_sigma: Gaussian blur of the final image in px (0 = none), a defocus stand-in.
        noise_sigma: standard deviation of additive Gaussian noise in grey levels.
        seed: seed of the noise generator, for reproducible images.

    Returns:
        An (height, width, 3) uint8 image.

    Raises:
        MarkerError: on a bad camera matrix, size or supersampling factor.
    """
    width, height = (int(v) for v in size)
    kk: NDArray[np.float64] = np.asarray(k, dtype=np.float64)
    if kk.shape != (3, 3) or width <= 0 or height <= 0 or supersample < 1:
        raise MarkerError(f"bad camera: K shape {kk.shape}, size {size}, supersample {supersample}")
    s = int(supersample)
    # Low-res continuous u maps to high-res s*(u + 0.5) - 0.5 (both with integer centres).
    k_hi = kk.copy()
    k_hi[:2, :] *= s
    k_hi[0, 2] += (s - 1) / 2.0
    k_hi[1, 2] += (s - 1) / 2.0
    canvas = np.full((height * s, width * s), float(background), np.float32)
    t_camera_world = pose_to_matrix(t_world_camera.inverse())
    depth = [
        float(np.linalg.norm((t_camera_world @ pose_to_matrix(m.pose))[:3, 3])) for m in markers
    ]
    for index in sorted(range(len(markers)), key=lambda i: -depth[i]):
        _draw_marker(canvas, markers[index], k_hi, t_camera_world, quiet_cells)
    image = cv2.resize(canvas, (width, height), interpolation=cv2.INTER_AREA) if s > 1 else canvas
    if blur_sigma > 0:
        image = cv2.GaussianBlur(image, (0, 0), blur_sigma)
    if noise_sigma > 0:
        rng = np.random.default_rng(seed)
        image = image + rng.normal(0.0, noise_sigma, image.shape).astype(np.float32)
    grey = np.clip(np.rint(image), 0, 255).astype(np.uint8)
    return np.repeat(grey[:, :, None], 3, axis=2)
