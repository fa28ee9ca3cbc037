"""The markers capability's operations on the simulated cell: rendered images, not ground truth.

Ground truth (scene.truth_*) is read only here, in the tests, to score what the operations
found in the rendered images.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import partial

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.markers import capability
from capabilities.markers.geometry import pose_errors
from capabilities.sim.session import SimCameraDevice, SimCellSession
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.executor import run_to_end
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ObjectModel, ParamType, Pose

pytestmark = pytest.mark.sim

# A joint configuration that keeps the arm out of the shoulder camera's view of the table.
OBSERVE = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)


def _op(op: str, **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, op=op, params=params)


def _run(cell: SimCellSession, tree: NodeSpec) -> tuple[Status, dict]:
    registry = CapabilityRegistry([capability()], cell=cell)
    built = build_tree(PlanSpec(tree), registry, clock=cell.clock)
    result = run_to_end(built, 100.0, timeout=30.0)
    return result.status, built.blackboard.snapshot()


def _observe(cell: SimCellSession) -> None:
    assert cell.sim.robot.move_joints(OBSERVE, speed=3.0, accel=6.0).wait(30)


def _object_pose(name: str, key: str) -> NodeSpec:
    return _op("markers.object_pose", object=Binding.fixed(ObjectModel(name), ParamType.OBJECT),
               pose=Binding.reference(key))  # fmt: skip


@pytest.fixture
def cell() -> Iterator[SimCellSession]:
    with SimCellSession(seed=2) as session:
        yield session


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_detect_gives_the_cup_and_bin_poses(seed: int) -> None:
    with SimCellSession(seed=seed) as cell:
        _observe(cell)
        tree = NodeSpec(NodeKind.SEQUENCE, children=[
            _op("markers.detect_markers"), _object_pose("cup", "CUP"), _object_pose("waste_bin", "BIN"),
        ])  # fmt: skip
        status, board = _run(cell, tree)
        assert status is Status.SUCCESS
        for key, name in (("CUP", "cup"), ("BIN", "waste_bin")):
            position_error, _ = pose_errors(board[key], cell.truth_pose(name))
            assert position_error < 0.005, (name, position_error)
            # yaw of the object (the cup is round: its yaw is free)
            if name == "waste_bin":
                _, angle = pose_errors(board[key], cell.truth_pose(name))
                assert math.degrees(angle) < 2.0


def test_marker_poses_from_320x240_images_within_5mm_and_2deg() -> None:
    with SimCellSession(seed=4, shoulder_size=(320, 240)) as cell:
        _observe(cell)
        status, _ = _run(cell, _op("markers.detect_markers"))
        assert status is Status.SUCCESS
        seen = {}
        for marker_id in cell.scene_layout()["marker_sizes"]:
            found = cell.world_model.marker(marker_id)
            if found is not None:
                seen[marker_id] = found[0]
        assert len(seen) >= 3, sorted(seen)  # the table's calibration markers at least
        for marker_id, pose in seen.items():
            truth = cell.sim.call(partial(cell.scene.truth_marker_pose, marker_id=marker_id))
            position_error, angle = pose_errors(pose, truth)
            assert position_error < 0.005 and math.degrees(angle) < 2.0, (
                marker_id,
                position_error,
                angle,
            )


def _displaced(nominal: Pose, shift_m: float, tilt_deg: float) -> Pose:
    direction = np.array([1.0, -1.0, 1.0]) / math.sqrt(3.0) * shift_m
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    half = math.radians(tilt_deg) / 2
    turn = Pose((0.0, 0.0, 0.0), (*(axis * math.sin(half)), math.cos(half)))
    rotated = turn.compose(Pose((0.0, 0.0, 0.0), nominal.orientation))
    return Pose(tuple(np.add(nominal.position, direction)), rotated.orientation)


def test_calibration_recovers_a_displaced_camera_within_5mm() -> None:
    with SimCellSession(seed=1, shoulder_size=(320, 240)) as cell:
        camera = cell.cameras["shoulder"]
        assert isinstance(camera, SimCameraDevice)  # a rendered camera: it can be displaced
        true_pose = _displaced(camera.extrinsics(), 0.03, 3.0)
        camera.displace_for_test(true_pose)
        before, _ = pose_errors(camera.extrinsics(), true_pose)
        assert before == pytest.approx(0.03, abs=1e-6)
        status, _ = _run(cell, _op("markers.calibrate_camera"))
        assert status is Status.SUCCESS
        position_error, angle = pose_errors(camera.extrinsics(), true_pose)
        assert position_error < 0.005 and math.degrees(angle) < 0.5


def test_an_object_out_of_sight_is_not_found(cell: SimCellSession) -> None:
    cell.sim.call(lambda client: cell.scene.remove(client, "cup"))
    _observe(cell)
    tree = NodeSpec(NodeKind.SEQUENCE, children=[
        _op("markers.detect_markers"),
        _op("markers.object_found", object=Binding.fixed(ObjectModel("cup"), ParamType.OBJECT)),
    ])  # fmt: skip
    status, _ = _run(cell, tree)
    assert status is Status.FAILURE
    registry = CapabilityRegistry([capability()], cell=cell)
    built = build_tree(PlanSpec(_object_pose("cup", "CUP")), registry, clock=cell.clock)
    assert run_to_end(built, 100.0, timeout=10.0).status is Status.FAILURE
    assert "cup has not been seen" in built.root.children[0].message
    assert built.root.children[0].error is ErrorType.NOT_FOUND


def test_markers_are_unavailable_without_cameras() -> None:
    registry = CapabilityRegistry([capability()], cell=NullCell())
    availability = registry.availability("markers.detect_markers")
    assert not availability.available
    assert "rgbd:shoulder" in availability.reason
