"""Sub-pixel refinement of a marker's corners by fitting lines to its four outer edges.

``cv2.cornerSubPix`` on the corners of a small marker (10-40 px a side) is biased inward by
0.3-1 px, because its window reaches the data cells. Here each side of the black square is
measured instead: many short intensity profiles across the edge give sub-pixel edge points
(the area under the normalised darkness profile is the distance to the edge, which is
unbiased for any symmetric blur), a robust line is fitted through them, and the corners are
the intersections of adjacent lines. This needs the white quiet zone around the marker.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

__all__ = ["refine_corners"]

_STEP = 0.1  # px between samples along a profile
_MIN_CONTRAST = 20.0  # grey levels between border and quiet zone, below which we give up


def _edge_points(
    grey: NDArray[np.float32],
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    centroid: NDArray[np.float64],
    half_width: float,
) -> NDArray[np.float64] | None:
    """Sub-pixel points on the edge from corner a to corner b, or None at low contrast."""
    length = float(np.linalg.norm(b - a))
    d = (b - a) / length
    n = np.array([-d[1], d[0]])
    if n @ (0.5 * (a + b) - centroid) < 0:
        n = -n  # the profile runs from inside (black border) to outside (quiet zone)
    margin = max(1.0, 0.1 * length)  # keep off the corners, where the other edge bends in
    s = np.linspace(margin, length - margin, max(3, int(length - 2 * margin)))
    t = np.arange(-half_width, half_width + 1e-9, _STEP)
    pts = a + s[:, None, None] * d + t[None, :, None] * n
    profiles = cv2.remap(
        grey, pts[..., 0].astype(np.float32), pts[..., 1].astype(np.float32), cv2.INTER_LINEAR
    )
    end = max(1, round(0.2 / _STEP))
    black = float(np.median(profiles[:, :end]))
    white = float(np.median(profiles[:, -end:]))
    if white - black < _MIN_CONTRAST:
        return None
    darkness = np.clip((white - profiles) / (white - black), 0.0, 1.0)
    offset = np.trapezoid(darkness, t, axis=1) - half_width
    return np.asarray(a + s[:, None] * d + offset[:, None] * n, dtype=np.float64)


def _intersect(l1: NDArray[np.float64], l2: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Intersection of two lines given as (vx, vy, x0, y0), None when near parallel."""
    a = np.array([[l1[0], -l2[0]], [l1[1], -l2[1]]])
    if abs(float(np.linalg.det(a))) < 1e-6:
        return None
    st = np.linalg.solve(a, np.array([l2[2] - l1[2], l2[3] - l1[3]]))
    return np.array([l1[2] + st[0] * l1[0], l1[3] + st[0] * l1[1]])


def _refine_once(grey: NDArray[np.float32], c: NDArray[np.float64]) -> NDArray[np.float64] | None:
    side = float(np.mean([np.linalg.norm(c[i] - c[(i + 1) % 4]) for i in range(4)]))
    # Half a profile: 0.6 of a cell stays inside the 1-cell black border and quiet zone.
    half_width = float(np.clip(0.6 * side / 6.0, 1.0, 3.0))
    centroid = c.mean(axis=0)
    lines = []
    for i in range(4):
        pts = _edge_points(grey, c[i], c[(i + 1) % 4], centroid, half_width)
        if pts is None:
            return None
        line = cv2.fitLine(pts.astype(np.float32), cv2.DIST_HUBER, 0, 0.01, 0.01)
        lines.append(np.asarray(line, dtype=np.float64).reshape(4))
    out = []
    for i in range(4):  # corner i joins side i-1 (from corner i-1) and side i
        p = _intersect(lines[(i - 1) % 4], lines[i])
        if p is None:
            return None
        out.append(p)
    return np.array(out)


def refine_corners(
    grey: NDArray[np.uint8], corners: NDArray[np.floating], iterations: int = 3
) -> tuple[NDArray[np.float64], bool]:
    """Refine a marker's 4 outer corners (4x2 px) on a grey image.

    Args:
        grey: the HxW uint8 image the corners were found in.
        corners: initial corners, within about a pixel of the truth, in ArUco order.
        iterations: edge fits, each starting from the previous corners.

    Returns:
        The refined corners and True, or the input corners and False when an edge has
        too little contrast (no quiet zone) or the refinement moved a corner implausibly.
    """
    initial = np.asarray(corners, dtype=np.float64).reshape(4, 2)
    image = grey.astype(np.float32)
    c = initial
    for _ in range(iterations):
        refined = _refine_once(image, c)
        if refined is None:
            return initial, False
        c = refined
    side = float(np.mean([np.linalg.norm(initial[i] - initial[(i + 1) % 4]) for i in range(4)]))
    if float(np.max(np.linalg.norm(c - initial, axis=1))) > max(2.0, 0.15 * side):
        return initial, False
    return c, True
