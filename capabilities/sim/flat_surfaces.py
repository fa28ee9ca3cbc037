"""Level rectangles facing up (the floor, the table top) drawn into a rendered frame by numpy.

pybullet's CPU renderer (TinyRenderer) pays for a triangle over its whole bounding box on
screen, hidden or not: the floor and the table top, two triangles each that span most of a
picture, cost the live view's mirror about half of every frame (measured with
``bench/cell_views.py``: the shoulder camera 22 -> 12 ms, the wrist camera 30 -> 14 ms of CPU
a frame without them). Such a surface is one plane, so where each pixel's ray meets it is a
few array operations: :class:`FlatSurfaces` puts the surface's colour and depth on every pixel
whose ray meets the rectangle in front of whatever was rendered there (a depth test, as the
renderer's own). Its colour is the renderer's: TinyRenderer lights a flat face with a
directional light and no view-dependent term, so one probe render of the surface gives the
colour of all its pixels. The pictures are the renderer's to the pixel
(``tests/capabilities/sim/test_flat_surfaces.py``).

Only the live view's mirror draws its floor and table top this way (``world.py``,
``live_view.py``); perception renders every surface with pybullet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capabilities.bullet import pybullet as p
from capabilities.geometry import pose_to_matrix
from engine.types import Pose

__all__ = ["FlatSurface", "FlatSurfaces", "shaded_colour"]

_PROBE_SIZE = 8  # pixels of the probe picture (its centre pixel shows the surface)


@dataclass(frozen=True)
class FlatSurface:
    """An axis-aligned rectangle at height ``z`` facing up (+z), drawn in ``rgba``.

    Attributes:
        z: height of the surface (m, world).
        x, y: its extent along the world's x and y axes (m).
        rgba: the colour a pybullet box of that top would have (0..1).
    """

    z: float
    x: tuple[float, float]
    y: tuple[float, float]
    rgba: tuple[float, float, float, float]


def shaded_colour(
    rgba: tuple[float, float, float, float], light_direction: tuple[float, float, float]
) -> np.ndarray:
    """The RGB (uint8) TinyRenderer gives the top of a box of colour ``rgba`` under this light:
    rendered once, looking straight down at such a box, in a pybullet client of its own.
    """
    client = p.connect(p.DIRECT)
    try:
        visual = p.createVisualShape(
            p.GEOM_BOX, halfExtents=(1.0, 1.0, 0.01), rgbaColor=rgba, physicsClientId=client
        )
        p.createMultiBody(0.0, -1, visual, basePosition=(0, 0, -0.01), physicsClientId=client)
        view = p.computeViewMatrix((0, 0, 1), (0, 0, 0), (0, 1, 0))
        projection = p.computeProjectionMatrixFOV(40.0, 1.0, 0.1, 3.0)
        rgba_image = p.getCameraImage(
            _PROBE_SIZE,
            _PROBE_SIZE,
            view,
            projection,
            renderer=p.ER_TINY_RENDERER,
            lightDirection=list(light_direction),
            shadow=0,
            flags=p.ER_NO_SEGMENTATION_MASK,
            physicsClientId=client,
        )[2]
    finally:
        p.disconnect(client)
    centre = _PROBE_SIZE // 2
    image = np.asarray(rgba_image, dtype=np.uint8).reshape(_PROBE_SIZE, _PROBE_SIZE, 4)
    return image[centre, centre, :3].copy()


class FlatSurfaces:
    """Draws level rectangles into RGB-D pictures rendered without them.

    Args:
        surfaces: the rectangles (none of them may hide a part of another: each is drawn
            where it is in front of what was rendered or drawn before it).
        light_direction: the light the camera renders with (for the surfaces' colours).
    """

    def __init__(
        self, surfaces: tuple[FlatSurface, ...], light_direction: tuple[float, float, float]
    ) -> None:
        self.surfaces = surfaces
        self.colours = [shaded_colour(s.rgba, light_direction) for s in surfaces]
        self._rays: dict[tuple[int, int, bytes], tuple[np.ndarray, np.ndarray]] = {}

    def draw(
        self,
        rgb: np.ndarray,
        depth: np.ndarray,
        K: np.ndarray,
        T_world_camera: Pose,
        near: float,
        far: float,
    ) -> None:
        """Draw every surface into ``rgb`` (HxWx3 uint8) and ``depth`` (HxW float32, metric
        depth along the optical axis, NaN where nothing was hit), in place.

        Args:
            rgb: the rendered picture's colours.
            depth: the rendered picture's depths.
            K: the picture's intrinsics (OpenCV convention).
            T_world_camera: the camera (OpenCV frame) in the world.
            near: the camera's near clipping distance (nothing nearer is drawn).
            far: the camera's far clipping distance (nothing farther is drawn).
        """
        a, b = self._pixel_rays(depth.shape, K)
        m = pose_to_matrix(T_world_camera)
        r, eye = m[:3, :3].astype(np.float32), m[:3, 3]
        # The ray of pixel (u, v) in the world is r @ (a, b, 1): its depth along the optical
        # axis is the ray's parameter t where it meets a plane z = const.
        rise = r[2, 0] * a + r[2, 1] * b + r[2, 2]
        for surface, colour in zip(self.surfaces, self.colours, strict=True):
            if eye[2] <= surface.z:  # seen from below: a surface facing up is culled
                continue
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.float32(surface.z - eye[2]) / rise
            x = eye[0] + t * (r[0, 0] * a + r[0, 1] * b + r[0, 2])
            y = eye[1] + t * (r[1, 0] * a + r[1, 1] * b + r[1, 2])
            hit = (t > near) & (t < far)
            hit &= (x >= surface.x[0]) & (x <= surface.x[1])
            hit &= (y >= surface.y[0]) & (y <= surface.y[1])
            hit &= ~(depth <= t)  # nothing rendered in front of it (NaN: nothing at all)
            rgb[hit] = colour
            depth[hit] = t[hit]

    def _pixel_rays(self, shape: tuple[int, ...], K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per pixel, the ray's x and y over its z in the camera frame (cached per size, K)."""
        h, w = shape[:2]
        key = (h, w, np.asarray(K, dtype=np.float64).tobytes())
        rays = self._rays.get(key)
        if rays is None:
            u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
            rays = ((u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1])
            rays = (rays[0].astype(np.float32), rays[1].astype(np.float32))
            self._rays[key] = rays
        return rays
