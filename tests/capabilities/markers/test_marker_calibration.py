"""Extrinsic calibration from table markers of known pose, rendered synthetically."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray

from capabilities.markers.calibration import calibrate_extrinsics, calibrate_eye_in_hand
from capabilities.markers.detection import detect_markers
from capabilities.markers.errors import MarkerError
from capabilities.markers.geometry import pose_errors
from capabilities.markers.synthetic import SyntheticMarker, look_at, render_markers
from engine.types import Pose
from tests.capabilities.markers.scenes import HEIGHT, WIDTH

LENGTH = 0.05


def _yaw(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


# Four markers lying face up on the table (world z up), spread over the camera's view.
TABLE = {
    0: Pose((-0.12, -0.10, 0.0), _yaw(0.3)),
    1: Pose((0.12, -0.10, 0.0), _yaw(-0.5)),
    2: Pose((0.12, 0.10, 0.0), _yaw(1.2)),
    3: Pose((-0.12, 0.10, 0.0), _yaw(2.5)),
}
TRUE_CAMERA = look_at((0.45, -0.25, 0.55), (0.0, 0.0, 0.0))


def _observe(camera: Pose, k: NDArray[np.float64], seed: int = 0) -> list:
    markers = [SyntheticMarker(i, pose, LENGTH) for i, pose in TABLE.items()]
    image = render_markers(markers, k, camera, (WIDTH, HEIGHT), noise_sigma=2.0, seed=seed)
    return detect_markers(image, k, LENGTH)


def test_recovers_a_displaced_camera(k: NDArray[np.float64]) -> None:
    # The configured (nominal) camera is 3 cm and 3 degrees off the true one.
    nudge = Pose(
        (0.03 / math.sqrt(3),) * 3,
        (math.sin(math.radians(1.5)), 0.0, 0.0, math.cos(math.radians(1.5))),
    )
    nominal = TRUE_CAMERA.compose(nudge)
    dp0, dr0 = pose_errors(nominal, TRUE_CAMERA)
    assert dp0 == pytest.approx(0.03) and math.degrees(dr0) == pytest.approx(3.0)
    observations = _observe(TRUE_CAMERA, k)
    assert [o.marker_id for o in observations] == [0, 1, 2, 3]
    camera, report = calibrate_extrinsics([observations], TABLE, k)
    dp, dr = pose_errors(camera, TRUE_CAMERA)
    print(
        f"calibration error {dp * 1000:.2f} mm {math.degrees(dr):.3f} deg, rms {report.rms_px:.3f} px"
    )
    assert dp < 0.005 and math.degrees(dr) < 1.0
    assert report.inliers == (0, 1, 2, 3) and report.outliers == () and report.points == 16
    assert report.rms_px < 0.5


def test_rejects_a_marker_with_a_wrong_known_pose(k: NDArray[np.float64]) -> None:
    wrong = dict(TABLE)
    wrong[2] = Pose((0.16, 0.12, 0.0), TABLE[2].orientation)  # moved 4.5 cm since measured
    camera, report = calibrate_extrinsics([_observe(TRUE_CAMERA, k)], wrong, k)
    dp, dr = pose_errors(camera, TRUE_CAMERA)
    assert report.outliers == (2,) and report.inliers == (0, 1, 3)
    assert report.per_marker_rms_px[2] > 3.0
    assert dp < 0.005 and math.degrees(dr) < 1.0


def test_several_images_and_unknown_markers(k: NDArray[np.float64]) -> None:
    images = [_observe(TRUE_CAMERA, k, seed=s) for s in (1, 2, 3)]
    known = {i: TABLE[i] for i in (0, 1, 2)}
    camera, report = calibrate_extrinsics(images, known, k)
    assert report.ignored == (3,) and report.images == 3 and report.points == 36
    dp, dr = pose_errors(camera, TRUE_CAMERA)
    assert dp < 0.005 and math.degrees(dr) < 1.0


def test_wrist_camera_hand_eye(k: NDArray[np.float64]) -> None:
    t_tool_camera = Pose((0.0, 0.06, 0.04), (0.05, -0.03, 0.02, 1.0))
    images, tools = [], []
    for i, eye in enumerate([(0.3, -0.2, 0.5), (-0.25, -0.3, 0.45), (0.05, 0.35, 0.55)]):
        camera = look_at(eye, (0.0, 0.0, 0.0))
        tool = camera.compose(t_tool_camera.inverse())
        images.append(_observe(camera, k, seed=i))
        tools.append(tool)
    estimate, report = calibrate_eye_in_hand(images, tools, TABLE, k)
    dp, dr = pose_errors(estimate, t_tool_camera)
    assert dp < 0.005 and math.degrees(dr) < 1.0 and report.outliers == ()


def test_nothing_known_seen_raises(k: NDArray[np.float64]) -> None:
    with pytest.raises(MarkerError, match="no marker with a known pose"):
        calibrate_extrinsics([_observe(TRUE_CAMERA, k)], {42: Pose()}, k)
    with pytest.raises(MarkerError, match="no marker with a known pose"):
        calibrate_extrinsics([[]], TABLE, k)
    with pytest.raises(MarkerError, match="tool poses"):
        calibrate_eye_in_hand([[]], [], TABLE, k)
