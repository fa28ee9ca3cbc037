"""The test renderer: markers land where the camera model puts them."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import marker_object_points, pose_to_matrix, transform_points
from capabilities.markers.synthetic import SyntheticMarker, look_at, project_points, render_markers
from engine.types import Pose

FACING = Pose((0.0, 0.0, 0.6), (1.0, 0.0, 0.0, 0.0))  # flipped about x: its face looks at us


def test_image_shape_dtype_and_background(k: NDArray[np.float64]) -> None:
    image = render_markers([], k, Pose(), (320, 240), background=100)
    assert image.shape == (240, 320, 3) and image.dtype == np.uint8
    assert np.all(image == 100)


def test_black_square_edges_sit_at_projected_corners(k: NDArray[np.float64]) -> None:
    length = 0.06
    image = render_markers([SyntheticMarker(0, FACING, length)], k, Pose(), (320, 240))
    corners = project_points(
        transform_points(pose_to_matrix(FACING), marker_object_points(length)), k, Pose()
    )
    left = corners[0, 0]
    row = image[round(float(corners[0, 1])) + 2, :, 0].astype(float)
    # The pixel that straddles the left edge is a blend of white and black in proportion.
    col = round(float(left))
    white_fraction = np.clip(left - (col - 0.5), 0.0, 1.0)  # pixel col spans col +- 0.5
    assert abs(row[col] - 255.0 * white_fraction) < 12.0
    assert row[col - 2] > 240 and row[col + 2] < 15


def test_back_face_and_behind_camera_are_not_drawn(k: NDArray[np.float64]) -> None:
    away = Pose((0.0, 0.0, 0.6))  # z out of the face points away from the camera
    behind = Pose((0.0, 0.0, -0.6), (1.0, 0.0, 0.0, 0.0))
    markers = [SyntheticMarker(0, away, 0.05), SyntheticMarker(1, behind, 0.05)]
    assert np.all(render_markers(markers, k, Pose(), (320, 240)) == 128)


def test_look_at_points_optical_axis_at_target() -> None:
    camera = look_at((0.5, 0.0, 0.7), (0.0, 0.0, 0.0))
    m = pose_to_matrix(camera)
    forward = m[:3, 2]
    assert np.allclose(forward, -np.array([0.5, 0.0, 0.7]) / np.hypot(0.5, 0.7))
    assert m[2, 1] < 0  # image down points down in the world
    with pytest.raises(MarkerError):
        look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0))


def test_bad_camera_raises(k: NDArray[np.float64]) -> None:
    with pytest.raises(MarkerError):
        render_markers([], np.eye(2), Pose(), (320, 240))
