"""Simulated RGB-D cameras: marker texture orientation, depth linearisation, point clouds."""

from __future__ import annotations

import math
from collections.abc import Iterator

import cv2
import numpy as np
import pybullet as p
import pytest

from capabilities.robot.camera_mounts import WRIST_MOUNT, look_at
from capabilities.sim.cameras import (
    CameraConfig,
    FixedMount,
    LinkMount,
    NoiseConfig,
    SimCamera,
    camera_fps,
    shoulder_camera,
    wrist_camera,
)
from capabilities.sim.cell import SimCell
from capabilities.sim.markers_texture import aruco_dictionary, marker_corners_in_marker_frame
from capabilities.sim.scene import SceneState, default_scene_path, load_scene, yaw_pose
from capabilities.sim.transforms import pose_to_matrix
from engine.types import Pose


@pytest.fixture
def client() -> Iterator[int]:
    cid = p.connect(p.DIRECT)
    try:
        yield cid
    finally:
        p.disconnect(cid)


def _detect(rgb: np.ndarray) -> dict[int, np.ndarray]:
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    detector = cv2.aruco.ArucoDetector(aruco_dictionary(), params)
    corners, ids, _ = detector.detectMarkers(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
    return (
        {}
        if ids is None
        else {int(i): c.reshape(4, 2) for i, c in zip(ids.ravel(), corners, strict=True)}
    )


def _project(points_world: np.ndarray, K: np.ndarray, camera: Pose) -> np.ndarray:
    t = np.linalg.inv(pose_to_matrix(camera))
    cam = points_world @ t[:3, :3].T + t[:3, 3]
    uv = cam @ K.T
    return uv[:, :2] / uv[:, 2:]


def _head_on(marker: Pose, distance: float, up_in_marker: tuple[float, float, float]) -> Pose:
    m = pose_to_matrix(marker)
    eye = m[:3, 3] + m[:3, 2] * distance
    return look_at(tuple(eye), tuple(m[:3, 3]), up=tuple(m[:3, :3] @ up_in_marker))


@pytest.mark.parametrize("size", [(320, 240), (640, 480)])
@pytest.mark.parametrize(
    ("marker_id", "up"),
    [
        (40, (0.0, 1.0, 0.0)),
        (40, (1.0, 1.0, 0.0)),
        (1, (0.3, -1.0, 0.0)),
        (10, (0.0, 1.0, 0.0)),
        (15, (-1.0, 0.2, 0.0)),
    ],
)
def test_marker_texture_orientation(
    client: int, size: tuple[int, int], marker_id: int, up: tuple[float, float, float]
) -> None:
    """cv2.aruco's corners (TL, TR, BR, BL) land on the marker frame's projected corners."""
    state = load_scene(client, default_scene_path("cup_to_bin"), seed=0)
    marker = state.truth_marker_pose(client, marker_id)
    side = state.marker_sizes()[marker_id]
    camera = SimCamera("t", CameraConfig(*size), FixedMount(_head_on(marker, 0.35, up)))
    frame = camera.capture(client)
    found = _detect(frame.rgb)
    assert marker_id in found
    t = pose_to_matrix(marker)
    corners = marker_corners_in_marker_frame(side) @ t[:3, :3].T + t[:3, 3]
    expected = _project(corners, frame.K, frame.T_world_camera)
    error = np.linalg.norm(found[marker_id] - expected, axis=1)
    assert error.max() < 1.0, error


def test_depth_of_a_plane_at_a_known_distance(client: int) -> None:
    load_scene(client, default_scene_path("empty"), seed=0)
    height = 0.8
    camera = SimCamera(
        "t",
        CameraConfig(640, 480, near=0.1, far=2.0),
        FixedMount(look_at((0.55, 0.0, height), (0.55, 0.0, 0.0), up=(1.0, 0.0, 0.0))),
    )
    frame = camera.capture(client)
    assert frame.depth.dtype == np.float32 and frame.depth.shape == (480, 640)
    assert frame.rgb.dtype == np.uint8 and frame.rgb.shape == (480, 640, 3)
    table = frame.depth[np.isfinite(frame.depth)]
    assert table.size > 0.9 * frame.depth.size
    # the marker planes stand 0.5 mm proud of the table; everything else is the table top
    assert np.abs(table - height).max() < 0.002


def test_tilted_view_points_lie_on_the_table(client: int) -> None:
    load_scene(client, default_scene_path("empty"), seed=0)
    frame = shoulder_camera(CameraConfig(320, 240)).capture(client)
    points = frame.point_cloud()
    on_table = (np.abs(points[:, 0] - 0.55) < 0.38) & (np.abs(points[:, 1]) < 0.58)
    assert on_table.sum() > 0.2 * frame.depth.size
    assert np.abs(points[on_table, 2]).max() < 0.002


def _cylinder_error(state: SceneState, client: int, points: np.ndarray) -> np.ndarray:
    pose = pose_to_matrix(state.truth_pose(client, "cup"))
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    near = (np.hypot(local[:, 0], local[:, 1]) < 0.06) & (local[:, 2] > 0.004)
    local = local[near]
    radial = np.abs(np.hypot(local[:, 0], local[:, 1]) - 0.04)
    top = np.abs(local[:, 2] - 0.1)
    return np.minimum(radial, top)


@pytest.mark.parametrize("size", [(320, 240), (640, 480)])
def test_point_cloud_lands_on_the_object(client: int, size: tuple[int, int]) -> None:
    state = load_scene(client, default_scene_path("cup_to_bin"), seed=7)
    frame = shoulder_camera(CameraConfig(*size)).capture(client)
    error = _cylinder_error(state, client, frame.point_cloud())
    assert error.size > 50
    # 1 mm: the marker planes float off the cup (up to 5 mm at the side marker's corners)
    assert np.median(error) < 0.001 and np.quantile(error, 0.9) < 0.003


def test_plate_holes_show_the_table_through_them(client: int) -> None:
    state = load_scene(client, default_scene_path("kitting"), seed=0)
    model = state.model("plate_4_holes")
    pose = pose_to_matrix(state.truth_pose(client, "plate_4_holes"))
    eye = pose[:3, 3] + [0.0, 0.0, 0.4]
    frame = SimCamera(
        "t",
        CameraConfig(640, 480),
        FixedMount(look_at(tuple(eye), tuple(pose[:3, 3]), up=(1, 0, 0))),
    ).capture(client)
    for hole in model.extra["holes"]:
        centre = pose[:3, :3] @ [*hole["position"], 0.0] + pose[:3, 3]
        u, v = np.rint(_project(centre[None, :], frame.K, frame.T_world_camera)[0]).astype(int)
        assert frame.depth[v, u] == pytest.approx(0.4, abs=0.002)  # the table, through the hole
    solid = _project(pose[None, :3, 3], frame.K, frame.T_world_camera)[0]
    u, v = np.rint(solid).astype(int)
    assert frame.depth[v, u] == pytest.approx(0.4 - model.dimensions[2], abs=0.002)


def test_shoulder_camera_sees_the_calibration_and_object_markers(client: int) -> None:
    load_scene(client, default_scene_path("cup_to_bin"), seed=0)
    found = _detect(shoulder_camera(CameraConfig(640, 480)).capture(client).rgb)
    assert {40, 41, 42, 43, 1} <= set(found)  # calibration markers and the cup's lid
    assert set(found) & {14, 15}  # a handle of the waste bin


def test_wrist_camera_follows_its_link(client: int) -> None:
    body = p.createMultiBody(
        1.0, -1, -1, [0.3, 0.0, 0.5],
        linkMasses=[0.1], linkCollisionShapeIndices=[-1], linkVisualShapeIndices=[-1],
        linkPositions=[[0.0, 0.0, 0.1]], linkOrientations=[[1.0, 0.0, 0.0, 0.0]],
        linkInertialFramePositions=[[0, 0, 0]], linkInertialFrameOrientations=[[0, 0, 0, 1]],
        linkParentIndices=[0], linkJointTypes=[p.JOINT_FIXED], linkJointAxis=[[0, 0, 1]],
        physicsClientId=client,
    )  # fmt: skip
    mount = Pose((0.0, 0.05, 0.0))
    camera = SimCamera("wrist", CameraConfig(), LinkMount(body, 0, mount))
    expected = Pose((0.3, 0.0, 0.6), (1.0, 0.0, 0.0, 0.0)).compose(mount)
    assert camera.pose(client).position == pytest.approx(expected.position, abs=1e-6)
    moved = yaw_pose(0.1, 0.2, 0.5, 0.0)
    p.resetBasePositionAndOrientation(
        body, moved.position, moved.orientation, physicsClientId=client
    )
    link = moved.compose(Pose((0.0, 0.0, 0.1), (1.0, 0.0, 0.0, 0.0)))
    frame = camera.capture(client, stamp=1.5)
    assert frame.stamp == 1.5 and frame.camera == "wrist"
    assert frame.T_world_camera.position == pytest.approx((0.1, 0.15, 0.6), abs=1e-6)
    assert frame.T_world_camera.orientation == pytest.approx(
        link.compose(mount).orientation, abs=1e-6
    )


def test_noise_is_off_by_default_and_seeded_when_on(client: int) -> None:
    load_scene(client, default_scene_path("empty"), seed=0)
    pose = look_at((0.55, 0.0, 0.8), (0.55, 0.0, 0.0), up=(1.0, 0.0, 0.0))
    clean = SimCamera("t", CameraConfig(), FixedMount(pose)).capture(client)
    noisy_cfg = CameraConfig(noise=NoiseConfig(seed=3))
    a = SimCamera("t", noisy_cfg, FixedMount(pose)).capture(client, stamp=0.0)
    b = SimCamera("t", noisy_cfg, FixedMount(pose)).capture(client, stamp=0.0)
    assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.depth, b.depth, equal_nan=True)
    diff = (a.depth - clean.depth)[np.isfinite(a.depth) & np.isfinite(clean.depth)]
    assert 0.0005 < np.std(diff) < 0.002  # about 1.5 mm * 0.8^2
    assert 0 < np.isnan(a.depth).mean() - np.isnan(clean.depth).mean() < 0.01


def test_intrinsics_match_the_field_of_view() -> None:
    K = CameraConfig(640, 480, fov_y=math.radians(60)).intrinsics()
    assert K[1, 1] == pytest.approx(240 / math.tan(math.radians(30)))
    assert K[0, 0] == K[1, 1] and (K[0, 2], K[1, 2]) == (320.0, 239.0)


def test_camera_fps_measures_something() -> None:
    assert camera_fps((160, 120), frames=2) > 1.0


def test_scene_and_cameras_in_the_cell(cell: SimCell) -> None:
    """The scene loads on the cell's physics thread onto the cell's own table."""
    state = cell.call(
        lambda c: load_scene(
            c,
            default_scene_path("cup_to_bin"),
            seed=1,
            make_table=False,
            table_top_z=cell.table_top_z,
        )
    )
    cell.wait_sim(0.3)
    cup = cell.call(lambda c: state.truth_pose(c, "cup"))
    assert cup.position[2] == pytest.approx(cell.table_top_z, abs=0.002)
    wrist = wrist_camera(cell.robot_body_id, cell.robot.flange_link(), CameraConfig(160, 120))
    frame = cell.call(wrist.capture)
    expected = cell.robot.flange_pose().compose(WRIST_MOUNT)
    assert frame.T_world_camera.position == pytest.approx(expected.position, abs=1e-3)
    assert np.isfinite(frame.depth).mean() > 0.9
    assert cell.call(shoulder_camera(CameraConfig(160, 120)).capture).rgb.shape == (120, 160, 3)
