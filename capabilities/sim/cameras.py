"""Simulated RGB-D cameras of the cell: a shoulder camera on a stand and a wrist camera.

A camera renders with pybullet's ER_TINY_RENDERER (CPU, no GL needed) and returns an
``RGBDFrame``: colour, metric depth along the optical axis, intrinsics ``K`` and the camera
pose in the world, in the OpenCV camera frame (x right, y down, z forward). Pixel (u, v) has
its centre at integer coordinates, as in OpenCV, so ``K`` can go straight to cv2 functions;
the principal point sits half a pixel off the image centre (see ``CameraConfig.intrinsics``).

pybullet's depth buffer holds the OpenGL window depth ``d`` in [0, 1]; the metric depth is
``z = far * near / (far - (far - near) * d)``. Pixels where nothing was hit (``d`` at the far
plane) read NaN.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from capabilities.bullet import pybullet as p
from capabilities.camera_source import RGBDFrame
from capabilities.robot.camera_mounts import SHOULDER_EYE, SHOULDER_TARGET, WRIST_MOUNT, look_at
from capabilities.sim.flat_surfaces import FlatSurfaces
from capabilities.sim.transforms import pose_to_matrix
from engine.types import Pose

__all__ = [
    "CameraConfig",
    "FixedMount",
    "LinkMount",
    "NoiseConfig",
    "RGBDFrame",
    "SimCamera",
    "camera_fps",
    "shoulder_camera",
    "wrist_camera",
]

# OpenCV camera frame -> OpenGL camera frame (x right, y up, z backward).
_CV_TO_GL = np.diag([1.0, -1.0, -1.0, 1.0])


@dataclass(frozen=True)
class NoiseConfig:
    """Mild sensor noise, like a structured-light RGB-D camera.

    Attributes:
        depth_sigma_at_1m: depth standard deviation (m) at 1 m; it grows with depth squared.
        dropout: fraction of valid depth pixels randomly lost (read NaN).
        rgb_sigma: colour noise standard deviation (0..255 scale).
        seed: seed of the camera's noise generator.
    """

    depth_sigma_at_1m: float = 0.0015
    dropout: float = 0.002
    rgb_sigma: float = 2.0
    seed: int = 0


@dataclass(frozen=True)
class CameraConfig:
    """Image size, optics and rendering options of a simulated camera.

    Attributes:
        width, height: image size in pixels (320x240 and 640x480 are the usual ones).
        fov_y: vertical field of view (rad).
        near, far: clipping distances (m); depth beyond ``far`` reads NaN.
        light_direction: direction toward the light (world), for shading.
        shadows: render shadows (slower).
        noise: sensor noise, None for a perfect sensor.
    """

    width: int = 320
    height: int = 240
    fov_y: float = math.radians(45.0)
    near: float = 0.1
    far: float = 3.0
    light_direction: tuple[float, float, float] = (0.4, 0.3, 1.0)
    shadows: bool = False
    noise: NoiseConfig | None = None

    def intrinsics(self) -> np.ndarray:
        """The 3x3 pinhole matrix K (square pixels, principal point at the image centre)."""
        f = (self.height / 2.0) / math.tan(self.fov_y / 2.0)
        # Measured, not assumed: TinyRenderer samples pixel column j at window x = j and
        # stores window row j as image row H-1-j, so with OpenCV's integer pixel centres the
        # principal point is (W/2, H/2 - 1) (tests/capabilities/sim/test_cameras.py).
        return np.array(
            [[f, 0.0, self.width / 2.0], [0.0, f, self.height / 2.0 - 1.0], [0, 0, 1.0]]
        )


@dataclass(frozen=True)
class FixedMount:
    """A camera fixed in the world (OpenCV camera frame)."""

    T_world_camera: Pose


@dataclass(frozen=True)
class LinkMount:
    """A camera on a link of a body: ``T_link_camera`` is the camera in the link frame."""

    body_id: int
    link_index: int
    T_link_camera: Pose = WRIST_MOUNT


class SimCamera:
    """A simulated RGB-D camera; call ``capture`` on the physics thread.

    Args:
        name: the camera's name (``shoulder``, ``wrist``).
        config: image size, optics and noise.
        mount: where the camera is (fixed in the world, or on a link).
    """

    def __init__(self, name: str, config: CameraConfig, mount: FixedMount | LinkMount) -> None:
        self.name = name
        self.config = config
        self.mount = mount
        self._rng = np.random.default_rng(config.noise.seed if config.noise else 0)
        self._projection = p.computeProjectionMatrixFOV(
            math.degrees(config.fov_y), config.width / config.height, config.near, config.far
        )

    def intrinsics(self) -> np.ndarray:
        """The 3x3 K of the images."""
        return self.config.intrinsics()

    def pose(self, client: int) -> Pose:
        """The camera (OpenCV frame) in the world now."""
        if isinstance(self.mount, FixedMount):
            return self.mount.T_world_camera
        state = p.getLinkState(
            self.mount.body_id,
            self.mount.link_index,
            computeForwardKinematics=True,
            physicsClientId=client,
        )
        return Pose(state[4], state[5]).compose(self.mount.T_link_camera)

    def capture(
        self, client: int, stamp: float | None = None, surfaces: FlatSurfaces | None = None
    ) -> RGBDFrame:
        """Render one RGB-D frame in ``client``.

        Args:
            client: pybullet client id.
            stamp: the time to stamp the frame with (default: the wall clock).
            surfaces: level surfaces the client lacks, drawn into the picture (the live
                view's mirror: ``flat_surfaces.py``).
        """
        c = self.config
        pose = self.pose(client)
        view = np.linalg.inv(pose_to_matrix(pose) @ _CV_TO_GL)
        _, _, rgba, buffer, _ = p.getCameraImage(
            c.width,
            c.height,
            viewMatrix=view.T.ravel().tolist(),
            projectionMatrix=self._projection,
            renderer=p.ER_TINY_RENDERER,
            lightDirection=list(c.light_direction),
            shadow=int(c.shadows),
            flags=p.ER_NO_SEGMENTATION_MASK,
            physicsClientId=client,
        )
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(c.height, c.width, 4)[:, :, :3]
        d = np.asarray(buffer, dtype=np.float64).reshape(c.height, c.width)
        depth = c.far * c.near / (c.far - (c.far - c.near) * d)
        depth[d >= 1.0 - 1e-6] = np.nan  # float32 buffer: the far plane reads 1 - 1e-7
        rgb, depth = np.ascontiguousarray(rgb), depth.astype(np.float32)
        if surfaces is not None:
            surfaces.draw(rgb, depth, self.intrinsics(), pose, c.near, c.far)
        if c.noise is not None:
            rgb, depth = self._add_noise(rgb, depth, c.noise)
        return RGBDFrame(
            rgb=rgb,
            depth=depth,
            K=self.intrinsics(),
            T_world_camera=pose,
            stamp=time.time() if stamp is None else stamp,
            camera=self.name,
        )

    def _add_noise(
        self, rgb: np.ndarray, depth: np.ndarray, noise: NoiseConfig
    ) -> tuple[np.ndarray, np.ndarray]:
        depth = depth.astype(np.float32)
        sigma = np.float32(noise.depth_sigma_at_1m) * np.nan_to_num(depth) ** 2
        depth += self._rng.standard_normal(depth.shape, dtype=np.float32) * sigma
        depth[self._rng.random(depth.shape, dtype=np.float32) < noise.dropout] = np.nan
        jitter = self._rng.standard_normal(rgb.shape, dtype=np.float32) * np.float32(
            noise.rgb_sigma
        )
        noisy = rgb.astype(np.float32) + jitter
        return np.clip(np.rint(noisy), 0, 255).astype(np.uint8), depth


def shoulder_camera(config: CameraConfig | None = None, pose: Pose | None = None) -> SimCamera:
    """The shoulder camera: on a stand behind and above the robot base, looking at the table."""
    return SimCamera(
        "shoulder",
        config or CameraConfig(),
        FixedMount(pose or look_at(SHOULDER_EYE, SHOULDER_TARGET)),
    )


def wrist_camera(
    body_id: int,
    flange_link: int,
    config: CameraConfig | None = None,
    T_flange_camera: Pose = WRIST_MOUNT,
) -> SimCamera:
    """The wrist camera on the flange link (tool0, z along the tool axis), looking along it.

    Its default near plane is 5 cm so that close parts stay in view.
    """
    return SimCamera(
        "wrist",
        config or CameraConfig(near=0.05, far=2.0),
        LinkMount(body_id, flange_link, T_flange_camera),
    )


def camera_fps(size: tuple[int, int] = (320, 240), frames: int = 10) -> float:
    """Frames per second of the shoulder camera over the cup_to_bin scene, in its own client.

    Measures rendering plus conversion to an RGBDFrame, in a fresh DIRECT client (for
    bench/sim.py). ``size`` is (width, height).
    """
    from capabilities.sim.scene import default_scene_path, load_scene

    client = p.connect(p.DIRECT)
    try:
        load_scene(client, default_scene_path("cup_to_bin"), seed=0)
        camera = shoulder_camera(CameraConfig(width=size[0], height=size[1]))
        camera.capture(client)  # the first frame pays for texture uploads
        start = time.perf_counter()
        for _ in range(frames):
            camera.capture(client)
        return frames / (time.perf_counter() - start)
    finally:
        p.disconnect(client)
