"""Flat parts (the metal plates): class by counting holes in a top view, pose from it.

The pixels of the plate's top face (heights near its top) are warped onto the table plane
at a fixed resolution (a homography from the fitted plane to the image), giving a top-down
binary image in which the plate is one blob and its holes are inner contours (OpenCV). Plates
of similar size differ by their number of holes, so the count decides the class; the blob's
minimum-area rectangle gives the centre and the axis, and the hole layout tells which way
round the plate lies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from capabilities.perception.config import RecognitionConfig
from capabilities.perception.models import ModelCloud
from capabilities.perception.scene_cloud import Cluster, SceneCloud

__all__ = ["PlateView", "TopView", "classify_plate", "top_view"]

_MARGIN = 0.02  # m around the cluster in the top view
_TOP_BAND = (0.6, 0.004)
_MIN_CONFIDENCE = 0.45  # the top face: from 60 % of the top height to 4 mm above it


@dataclass
class TopView:
    """A binary top-down image of a flat cluster.

    Attributes:
        image: uint8 0/255, row v and column u at table (x0 + u*res, y0 + v*res).
        origin: (x0, y0) in the table frame (m); resolution: m per pixel.
        outline: the plate's outer contour (pixels); holes: centres of its holes (table xy, m)
        area: the plate's area (m^2, holes filled).
    """

    image: np.ndarray
    origin: tuple[float, float]
    resolution: float
    outline: np.ndarray
    holes: list[tuple[float, float]]
    area: float

    def to_table(self, u: float, v: float) -> tuple[float, float]:
        return self.origin[0] + u * self.resolution, self.origin[1] + v * self.resolution


@dataclass(frozen=True)
class PlateView:
    """A plate recognised from its top view: class, pose (table frame), confidence."""

    model: str
    x: float
    y: float
    yaw: float
    holes: int
    confidence: float


def top_view(scene: SceneCloud, cluster: Cluster, config: RecognitionConfig) -> TopView | None:
    """The top-down binary image of a flat cluster, or None when it shows no single blob."""
    top, res = cluster.top, config.top_view_resolution
    lo = cluster.points[:, :2].min(axis=0) - _MARGIN
    hi = cluster.points[:, :2].max(axis=0) + _MARGIN
    size = np.ceil((hi - lo) / res).astype(int)
    inside = np.all((scene.table_xy >= lo) & (scene.table_xy <= hi), axis=-1)
    band = (scene.heights > _TOP_BAND[0] * top) & (scene.heights < top + _TOP_BAND[1])
    mask = (inside & band).astype(np.uint8) * 255
    # top-view pixel (u, v) -> table point (x0 + u res, y0 + v res, top) -> image pixel
    to_table = np.array([[res, 0.0, lo[0]], [0.0, res, lo[1]], [0.0, 0.0, 1.0]])
    t = scene.T_camera_table
    plane_to_camera = np.column_stack((t[:3, 0], t[:3, 1], t[:3, 2] * top + t[:3, 3]))
    homography = scene.K @ plane_to_camera @ to_table
    warped = cv2.warpPerspective(
        mask,
        homography,
        (int(size[0]), int(size[1])),
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
    )
    image = np.where(warped > 127, 255, 0).astype(np.uint8)
    contours, hierarchy = cv2.findContours(image, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return None
    outer = max(
        (i for i in range(len(contours)) if hierarchy[0][i][3] < 0),
        key=lambda i: cv2.contourArea(contours[i]),
    )
    min_area = config.min_hole_area / res**2
    holes = []
    for i, contour in enumerate(contours):
        if hierarchy[0][i][3] == outer and cv2.contourArea(contour) >= min_area:
            m = cv2.moments(contour)
            holes.append((m["m10"] / m["m00"], m["m01"] / m["m00"]))
    view = TopView(image, (float(lo[0]), float(lo[1])), res, contours[outer], [], 0.0)
    view.holes = [view.to_table(u, v) for u, v in holes]
    view.area = cv2.contourArea(contours[outer]) * res**2
    return view


def _model_holes(model: ModelCloud, x: float, y: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([h["position"] for h in model.holes], dtype=float).reshape(-1, 2)
    return np.column_stack(
        (x + c * local[:, 0] - s * local[:, 1], y + s * local[:, 0] + c * local[:, 1])
    )


def _hole_mismatch(model: ModelCloud, x: float, y: float, yaw: float, seen: np.ndarray) -> float:
    """Mean distance (m) from each model hole to the nearest hole seen."""
    expected = _model_holes(model, x, y, yaw)
    if len(seen) == 0 or len(expected) == 0:
        return math.inf
    d = np.linalg.norm(expected[:, None, :] - seen[None, :, :], axis=-1)
    return float(d.min(axis=1).mean())


def _place(view: TopView, model: ModelCloud) -> tuple[float, float, float, float]:
    """(x, y, yaw, hole mismatch) of the model on the blob: the rectangle's centre, its long
    side along the model's long side, and of the turns the one whose holes match best.
    """
    (cu, cv), (w, h), angle = cv2.minAreaRect(view.outline.astype(np.float32))
    x, y = view.to_table(cu, cv)
    yaw = math.radians(angle) + (0.0 if w >= h else math.pi / 2)
    dims = model.spec.dimensions
    if dims[1] > dims[0]:
        yaw += math.pi / 2
    seen = np.array(view.holes, dtype=float).reshape(-1, 2)
    turns = 4 if abs(dims[0] - dims[1]) < 0.01 else 2
    options = [yaw + k * 2 * math.pi / turns for k in range(turns)]
    scored = [(_hole_mismatch(model, x, y, a, seen), a) for a in options]
    mismatch, best = min(scored)
    return x, y, best, mismatch


def classify_plate(view: TopView, plates: list[ModelCloud]) -> PlateView | None:
    """The plate model with as many holes as the view shows (size as the tie-breaker and
    as the fallback when the count matches no model); None when nothing fits the outline.
    """
    if not plates:
        return None
    count = len(view.holes)

    def size_match(m: ModelCloud) -> float:
        area = m.spec.dimensions[0] * m.spec.dimensions[1]
        return min(area, view.area) / max(area, view.area)

    by_count = [m for m in plates if len(m.holes) == count]
    candidates = by_count or plates
    model = max(candidates, key=size_match)
    similarity = size_match(model)
    if similarity < 0.6:
        return None
    x, y, yaw, mismatch = _place(view, model)
    confidence = similarity * (1.0 if by_count else 0.5)
    if math.isfinite(mismatch) and mismatch > 0.01:
        confidence *= 0.5
    if confidence < _MIN_CONFIDENCE:  # a plate half hidden: better unseen than misnamed
        return None
    return PlateView(model.name, x, y, yaw, count, confidence)
