"""Recorded RGB-D frames: written from any camera source, read back as one; markers run the same."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.camera_source import CameraSource, RGBDFrame
from capabilities.camera_sources import open_source
from capabilities.errors import CapabilityError
from capabilities.markers import capability
from capabilities.recorded_frames import FrameRecorder, RecordedCamera, RecordingError, record
from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig
from engine.build import build_tree
from engine.executor import run_to_end
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import Pose

OBSERVE = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)  # the arm out of the shoulder camera's view


def _frame() -> RGBDFrame:
    rng = np.random.default_rng(3)
    depth = rng.uniform(0.3, 2.5, (24, 32)).astype(np.float32)
    depth[2, 5] = np.nan
    K = np.array([[40.0, 0.0, 15.5], [0.0, 40.0, 11.5], [0.0, 0.0, 1.0]])
    rgb = rng.integers(0, 255, (24, 32, 3), dtype=np.uint8)
    return RGBDFrame(rgb, depth, K, Pose((0.1, 0.2, 1.5), (1.0, 0.0, 0.0, 0.0)), 4.25, "top")


def test_a_recording_reads_back_frame_for_frame(tmp_path: Path) -> None:
    frame = _frame()
    recorder = FrameRecorder(tmp_path / "rec", "top")
    recorder.add(frame)
    camera = RecordedCamera(tmp_path / "rec")
    assert isinstance(camera, CameraSource)
    back = camera.capture()
    assert np.array_equal(back.rgb, frame.rgb)
    assert np.allclose(back.depth, frame.depth, atol=6e-5, equal_nan=True)  # 0.1 mm steps
    assert np.isnan(back.depth[2, 5])
    assert np.array_equal(back.K, frame.K) and back.T_world_camera == frame.T_world_camera
    assert (back.stamp, back.camera, camera.name, camera.on_wrist) == (4.25, "top", "top", False)
    calibrated = Pose((0.0, 0.0, 2.0))
    camera.set_extrinsics(calibrated)
    assert camera.capture().T_world_camera == calibrated == camera.extrinsics()


def test_a_frame_asked_at_most_so_wide_has_the_points_of_every_nth_pixel(
    tmp_path: Path,
) -> None:
    frame = _frame()
    assert frame.at_most(None) is frame and frame.at_most(32) is frame
    small = frame.at_most(12)  # 32 columns: every 3rd, 11 wide
    assert small.depth.shape == (8, 11) and small.rgb.shape == (8, 11, 3)
    assert np.allclose(small.point_cloud(), frame.point_cloud(3))
    assert np.array_equal(small.point_colors(), frame.point_colors(3))
    FrameRecorder(tmp_path / "rec", "top").add(frame)
    recorded = RecordedCamera(tmp_path / "rec").capture(max_width=16)
    assert recorded.depth.shape == (12, 16)
    assert np.allclose(recorded.point_cloud(), frame.point_cloud(2), atol=1e-4)


def test_a_broken_recording_names_file_and_field(tmp_path: Path) -> None:
    FrameRecorder(tmp_path, "top").add(_frame())
    index = json.loads((tmp_path / "recording.json").read_text())
    index["frames"][0]["K"] = [[1, 0, 0], [0, 1, 0]]
    (tmp_path / "recording.json").write_text(json.dumps(index))
    with pytest.raises(RecordingError, match=r"recording\.json.*\$\.frames\[0\]\.K.*3x3"):
        RecordedCamera(tmp_path)
    with pytest.raises(RecordingError, match=r"recording\.json"):
        RecordedCamera(tmp_path / "nowhere")
    with pytest.raises(CapabilityError, match="source 'sim' cannot be opened here"):
        open_source("top", "sim", "")


def _detected(cell: object) -> dict[int, Pose]:
    registry = CapabilityRegistry([capability()], cell=cell)
    tree = build_tree(PlanSpec(NodeSpec(NodeKind.OPERATION, op="markers.detect_markers")),
                      registry, clock=cell.clock)  # type: ignore[attr-defined]  # fmt: skip
    assert run_to_end(tree, 100.0, timeout=30.0).status is Status.SUCCESS
    world = cell.world_model  # type: ignore[attr-defined]
    found = {i: world.marker(i) for i in range(50)}
    return {i: entry[0] for i, entry in found.items() if entry is not None}


@pytest.mark.sim
def test_markers_find_the_same_poses_in_recorded_frames_as_in_rendered_ones(
    tmp_path: Path,
) -> None:
    from capabilities.cells import open_cell
    from capabilities.sim.session import SimCellSession

    with SimCellSession(seed=0) as cell:
        assert cell.sim.robot.move_joints(OBSERVE, speed=3.0, accel=6.0).wait(30)
        live = _detected(cell)
        record(cell.cameras["shoulder"], tmp_path / "frames" / "shoulder")
    assert len(live) >= 2
    data = json.loads(DEFAULT_CONFIG_PATH.read_text("utf-8"))
    data["cameras"]["shoulder"]["source"] = {"kind": "recorded", "path": "frames/shoulder"}
    cell_file = tmp_path / "replay.cell.json"
    cell_file.write_text(json.dumps(data), "utf-8")
    assert CellConfig.load(cell_file).cameras["shoulder"].source == "recorded"
    with open_cell(str(cell_file), seed=0) as replay:
        assert isinstance(replay.cameras["shoulder"], RecordedCamera)
        again = _detected(replay)
    assert set(again) == set(live)
    for marker_id, pose in live.items():
        assert math.dist(pose.position, again[marker_id].position) < 0.002, marker_id
