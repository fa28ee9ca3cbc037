"""Scene helpers shared by the marker tests."""

from __future__ import annotations

import math

import numpy as np

from capabilities.markers.geometry import matrix_to_pose, rotvec_to_matrix
from engine.types import Pose

WIDTH, HEIGHT = 320, 240


def random_marker_pose(rng: np.random.Generator, view_deg: tuple[float, float]) -> Pose:
    """A marker pose in the camera frame, in view, 0.4-0.9 m away, facing the camera.

    The angle between the marker normal and the line of sight is drawn from ``view_deg``;
    the spin about the normal is uniform.
    """
    distance = rng.uniform(0.4, 0.9)
    ax, ay = rng.uniform(-1.0, 1.0, 2) * np.radians([20.0, 14.0])
    centre = np.array([math.tan(ax), math.tan(ay), 1.0])
    centre *= distance / np.linalg.norm(centre)
    z = -centre / np.linalg.norm(centre)  # normal toward the camera
    x = np.cross([0.0, 1.0, 0.0], z)
    x /= np.linalg.norm(x)
    facing = np.stack([x, np.cross(z, x), z], axis=1)
    axis = np.cross(z, rng.normal(size=3))
    axis /= np.linalg.norm(axis)
    tilt = rotvec_to_matrix(axis * math.radians(rng.uniform(*view_deg)))
    spin = rotvec_to_matrix([0.0, 0.0, rng.uniform(-math.pi, math.pi)])
    m = np.eye(4)
    m[:3, :3] = tilt @ facing @ spin
    m[:3, 3] = centre
    return matrix_to_pose(m)
