"""Marker detection and pose: accuracy on rendered images, conventions, bad input."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from capabilities.markers.detection import (
    ARUCO_DICTIONARY,
    detect_markers,
    marker_pose_world,
    object_pose_from_marker,
)
from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import pose_errors, pose_to_matrix
from capabilities.markers.synthetic import SyntheticMarker, render_markers
from engine.types import Pose
from tests.capabilities.markers.scenes import HEIGHT, WIDTH, random_marker_pose

UPRIGHT = (1.0, 0.0, 0.0, 0.0)  # x right, y up in the image, z toward the camera


def _render(k: NDArray[np.float64], *markers: SyntheticMarker, seed: int = 0) -> NDArray[np.uint8]:
    return render_markers(list(markers), k, Pose(), (WIDTH, HEIGHT), noise_sigma=2.0, seed=seed)


def test_pose_accuracy_over_random_poses(k: NDArray[np.float64]) -> None:
    rng = np.random.default_rng(2024)
    errors = []
    for i in range(40):
        truth, length = random_marker_pose(rng, (15.0, 50.0)), rng.uniform(0.04, 0.06)
        found = detect_markers(_render(k, SyntheticMarker(i, truth, length), seed=i), k, length)
        assert [o.marker_id for o in found] == [i]
        dp, dr = pose_errors(found[0].pose, truth)
        errors.append((dp * 1000.0, math.degrees(dr)))
    e = np.array(errors)
    print("position mm p50/p90/max", np.percentile(e[:, 0], [50, 90, 100]).round(2))
    print("rotation deg p50/p90/max", np.percentile(e[:, 1], [50, 90, 100]).round(2))
    assert e[:, 0].max() < 5.0 and e[:, 1].max() < 2.0
    assert np.median(e[:, 0]) < 1.5 and np.median(e[:, 1]) < 0.5


def test_upright_marker_axes_and_corner_order(k: NDArray[np.float64]) -> None:
    truth = Pose((0.02, -0.01, 0.5), UPRIGHT)
    found = detect_markers(_render(k, SyntheticMarker(7, truth, 0.05)), k, 0.05)
    assert len(found) == 1
    obs = found[0]
    r = pose_to_matrix(obs.pose)[:3, :3]
    assert r[:, 0] @ [1, 0, 0] > 0.99  # marker x: image right
    assert r[:, 1] @ [0, -1, 0] > 0.99  # marker y: image up
    assert r[:, 2] @ [0, 0, -1] > 0.99  # marker z: toward the camera
    tl, tr, br, bl = obs.corners
    assert tl[0] < tr[0] and tl[1] < bl[1] and br[0] > bl[0] and br[1] > tr[1]
    assert obs.reprojection_error < 0.2 and 0.0 < obs.confidence <= 1.0


def test_spun_marker_reports_spin(k: NDArray[np.float64]) -> None:
    # Spun 90 degrees about its normal: the texture's top now points to the image's left.
    spin = Pose((0.0, 0.0, 0.0), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))
    truth = Pose((0.0, 0.0, 0.5), UPRIGHT).compose(spin)
    obs = detect_markers(_render(k, SyntheticMarker(3, truth, 0.05)), k, 0.05)[0]
    r = pose_to_matrix(obs.pose)[:3, :3]
    assert r[:, 1] @ [-1, 0, 0] > 0.99
    assert obs.corners[0][0] < obs.corners[2][0] and obs.corners[0][1] > obs.corners[2][1]


def test_first_corner_is_texture_top_left_without_renderer() -> None:
    # Independent of synthetic.py: the printed texture itself, upright, on white paper.
    dictionary = cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY)
    texture = cv2.aruco.generateImageMarker(dictionary, 5, 120)
    image = cv2.copyMakeBorder(texture, 40, 40, 40, 40, cv2.BORDER_CONSTANT, value=255)
    k = np.array([[200.0, 0.0, 99.5], [0.0, 200.0, 99.5], [0.0, 0.0, 1.0]])
    obs = detect_markers(np.dstack([image] * 3), k, 0.1)[0]
    assert np.allclose(
        obs.corners, [[39.5, 39.5], [159.5, 39.5], [159.5, 159.5], [39.5, 159.5]], atol=0.3
    )


def test_frontal_marker_is_flagged_ambiguous(k: NDArray[np.float64]) -> None:
    frontal = detect_markers(
        _render(k, SyntheticMarker(1, Pose((0, 0, 0.8), UPRIGHT), 0.04)), k, 0.04
    )
    tilted_pose = Pose((0, 0, 0.5), UPRIGHT).compose(
        Pose((0, 0, 0), (math.sin(0.3), 0, 0, math.cos(0.3)))
    )
    tilted = detect_markers(_render(k, SyntheticMarker(1, tilted_pose, 0.05)), k, 0.05)
    assert frontal[0].ambiguity > 0.5 > tilted[0].ambiguity
    assert frontal[0].confidence < tilted[0].confidence


def test_length_mapping_selects_markers_and_scales_pose(k: NDArray[np.float64]) -> None:
    a = SyntheticMarker(2, Pose((-0.08, 0.0, 0.6), UPRIGHT), 0.04)
    b = SyntheticMarker(9, Pose((0.08, 0.0, 0.6), UPRIGHT), 0.06)
    image = _render(k, a, b)
    both = detect_markers(image, k, {2: 0.04, 9: 0.06})
    assert [o.marker_id for o in both] == [2, 9]
    for obs, marker in zip(both, (a, b), strict=True):
        assert pose_errors(obs.pose, marker.pose)[0] < 0.005
    only = detect_markers(image, k, {9: 0.06}, dist=np.zeros(5))
    assert [o.marker_id for o in only] == [9]


def test_world_and_object_poses() -> None:
    obs_pose = Pose((0.1, 0.0, 0.5), UPRIGHT)
    camera = Pose((1.0, 2.0, 0.8), (0.0, 0.7071, 0.0, 0.7071))
    obs = type("Obs", (), {"pose": obs_pose})()
    world = marker_pose_world(obs, camera)  # type: ignore[arg-type]  # a stand-in observation with only a pose
    assert np.allclose(pose_to_matrix(world), pose_to_matrix(camera) @ pose_to_matrix(obs_pose))
    marker_in_object = Pose((0.0, 0.0, 0.03), (0.0, 0.0, 0.3826834, 0.9238795))
    obj = object_pose_from_marker(world, marker_in_object)
    assert pose_errors(obj.compose(marker_in_object), world)[0] < 1e-12


def test_empty_image_gives_no_markers(k: NDArray[np.float64]) -> None:
    assert detect_markers(np.full((HEIGHT, WIDTH, 3), 128, np.uint8), k, 0.05) == []
    assert detect_markers(np.zeros((HEIGHT, WIDTH), np.uint8), k, 0.05) == []


@pytest.mark.parametrize(
    "image",
    [
        np.zeros((240, 320, 3), np.float32),
        np.zeros((240, 320, 4), np.uint8),
        np.zeros((240, 320, 3, 1), np.uint8),
        [[0, 0], [0, 0]],
    ],
)
def test_bad_image_raises(k: NDArray[np.float64], image: object) -> None:
    with pytest.raises(MarkerError):
        detect_markers(image, k, 0.05)  # type: ignore[arg-type]  # a bad image on purpose


@pytest.mark.parametrize(
    ("camera", "lengths", "dist"),
    [
        (np.eye(2), 0.05, None),
        (np.diag([0.0, 1.0, 1.0]), 0.05, None),
        (None, -0.05, None),
        (None, {1: 0.0}, None),
        (None, {1: "5 cm"}, None),
        (None, float("nan"), None),
        (None, "5 cm", None),
        (None, 0.05, np.zeros(3)),
    ],
)
def test_bad_camera_or_length_raises(
    k: NDArray[np.float64], camera: object, lengths: object, dist: object
) -> None:
    image = np.full((HEIGHT, WIDTH, 3), 128, np.uint8)
    with pytest.raises(MarkerError):
        detect_markers(image, k if camera is None else camera, lengths, dist)  # type: ignore[arg-type]  # bad arguments on purpose
