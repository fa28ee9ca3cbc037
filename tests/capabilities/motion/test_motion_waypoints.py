"""motion: smart waypoints (relative to a detected object or a marker) and symmetries."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from capabilities.motion.geometry import axis_rotation, rotation_between
from capabilities.motion.symmetry import NO_SYMMETRY, ObjectSymmetry, SymmetryTable
from capabilities.motion.targets import symmetric_tool_poses
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import angle_between, distance, down_at
from capabilities.world_model import Detection
from engine.status import Status
from engine.types import Pose, Waypoint, WaypointFrame
from tests.capabilities.motion.plans import DOWN, op, run_plan, seq

MM = 1e-3
HALF_DEG = math.radians(0.5)
Z = (0.0, 0.0, 1.0)


def _yawed(x: float, y: float, yaw: float) -> Pose:
    return Pose((x, y, 0.0), axis_rotation(Z, yaw).orientation)


# ---------------------------------------------------------------- pure geometry


def test_discrete_symmetry_picks_the_least_wrist_rotation() -> None:
    obj = _yawed(0.5, 0.0, 0.3)
    tool_in_obj = Pose((0.02, 0.0, 0.1), DOWN)
    current = obj.compose(axis_rotation(Z, math.pi / 2 + 0.1)).compose(tool_in_obj)
    poses = symmetric_tool_poses(
        obj, tool_in_obj, ObjectSymmetry(Z, (0.0, math.pi / 2, math.pi, 1.5 * math.pi)), current
    )
    assert len(poses) == 4
    assert rotation_between(current, poses[0]) == pytest.approx(0.1, abs=1e-9)
    want = obj.compose(axis_rotation(Z, math.pi / 2)).compose(tool_in_obj)
    assert distance(poses[0], want) < 1e-9  # the offset turns with the symmetry


def test_continuous_symmetry_needs_no_wrist_rotation_when_the_axis_allows() -> None:
    obj = _yawed(0.4, 0.1, -1.0)
    tool_in_obj = Pose((0.05, 0.0, 0.12), DOWN)
    current = down_at(0.3, 0.3, 0.3, yaw=1.234)
    best = symmetric_tool_poses(obj, tool_in_obj, ObjectSymmetry(Z, None), current)[0]
    assert rotation_between(current, best) < 1e-9
    assert math.hypot(best.position[0] - 0.4, best.position[1] - 0.1) == pytest.approx(0.05)
    assert best.position[2] == pytest.approx(0.12)


def test_no_symmetry_gives_the_taught_pose() -> None:
    obj, tool_in_obj = _yawed(0.4, 0.1, 0.7), Pose((0.0, 0.0, 0.1), DOWN)
    poses = symmetric_tool_poses(obj, tool_in_obj, NO_SYMMETRY, down_at(0, 0, 0))
    assert poses == [obj.compose(tool_in_obj)]


def test_symmetries_come_from_the_object_library() -> None:
    table = SymmetryTable()
    assert table.lookup("cup")[0].continuous
    assert table.lookup("plate_4_holes")[0].angles == pytest.approx(
        (0.0, math.pi / 2, math.pi, 1.5 * math.pi)
    )
    symmetry, note = table.lookup("no_such_thing")
    assert symmetry is NO_SYMMETRY and "no_such_thing" in note


# ---------------------------------------------------------------- on the simulated cell


@pytest.fixture(scope="module")
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty") as cell:
        yield cell


def _detect(session: SimCellSession, name: str, pose: Pose) -> None:
    session.world_model.replace("test", [Detection(name, pose, 1.0, session.clock(), "test")])


@pytest.mark.sim
def test_waypoint_relative_to_a_detected_plate_uses_its_nearest_symmetry(
    session: SimCellSession,
) -> None:
    plate = _yawed(0.5, -0.1, 1.2)
    _detect(session, "plate_4_holes", plate)
    taught = Pose((0.0, 0.0, 0.1), DOWN)
    above = Waypoint("above plate", WaypointFrame.OBJECT, taught, reference="plate_4_holes")
    start = down_at(0.4, 0.0, 0.25, yaw=0.2)
    candidates = [
        plate.compose(axis_rotation(Z, k * math.pi / 2)).compose(taught) for k in range(4)
    ]
    nearest = min(candidates, key=lambda c: rotation_between(start, c))
    assert rotation_between(start, candidates[0]) > math.pi / 4  # the taught pose is not it
    plan = seq(
        op("motion.move_to", "start", target=start),
        op("motion.move_to", "above plate", target=above),
        op("motion.current_pose", pose="$P"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    got = run.value("P")
    assert distance(got, nearest) < MM and angle_between(got, nearest) < HALF_DEG


@pytest.mark.sim
def test_waypoint_relative_to_a_bound_pose_and_to_a_marker(session: SimCellSession) -> None:
    cup = _yawed(0.45, 0.15, 0.0)
    side = Waypoint("cup side", WaypointFrame.OBJECT, Pose((0.1, 0.0, 0.15), DOWN), reference="cup")
    marker = Pose((0.5, -0.2, 0.0), axis_rotation(Z, 0.4).orientation)
    session.world_model.set_markers({7: marker}, session.clock())
    over_marker = Waypoint(
        "over 7", WaypointFrame.MARKER, Pose((0.0, 0.0, 0.2), DOWN), reference="7"
    )
    plan = seq(
        op("motion.move_to", "start", target=down_at(0.4, 0.0, 0.25, yaw=0.3)),
        op("motion.current_pose", "before", pose="$BEFORE"),
        op("motion.move_to", "cup side", target=side, reference=cup, mode="linear"),
        op("motion.current_pose", "at cup", pose="$CUP"),
        op("motion.move_to", "marker", target=over_marker),
        op("motion.current_pose", "at marker", pose="$MARKER"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    at_cup = run.value("CUP")
    # The cup is round: the tool keeps its orientation, 100 mm from the axis, 150 mm up.
    assert angle_between(at_cup, run.value("BEFORE")) < HALF_DEG
    assert math.hypot(at_cup.position[0] - 0.45, at_cup.position[1] - 0.15) == pytest.approx(
        0.1, abs=MM
    )
    assert at_cup.position[2] == pytest.approx(0.15, abs=MM)
    assert over_marker.pose is not None
    want = marker.compose(over_marker.pose)
    assert distance(run.value("MARKER"), want) < MM
    assert angle_between(run.value("MARKER"), want) < HALF_DEG


@pytest.mark.sim
def test_relative_waypoint_without_a_detection_or_marker_fails_clearly(
    session: SimCellSession,
) -> None:
    session.world_model.clear()
    in_bin = Waypoint(
        "in bin", WaypointFrame.OBJECT, Pose((0.0, 0.0, 0.1), DOWN), reference="kit_bin"
    )
    run = run_plan(session, op("motion.move_to", "bin", target=in_bin))
    assert (
        run.status is Status.FAILURE and "no 'kit_bin' has been detected" in run.messages()["bin"]
    )
    unseen = Waypoint("m", WaypointFrame.MARKER, Pose((0.0, 0.0, 0.1), DOWN), reference="9")
    run = run_plan(session, op("motion.move_to", "marker", target=unseen))
    assert run.status is Status.FAILURE and "marker 9 has not been seen" in run.messages()["marker"]


@pytest.mark.sim
def test_an_unreachable_relative_waypoint_names_every_symmetry_tried(
    session: SimCellSession,
) -> None:
    _detect(session, "cup", _yawed(0.45, 0.15, 0.0))
    far = Waypoint("far", WaypointFrame.OBJECT, Pose((0.0, 0.0, 1.5), DOWN), reference="cup")
    run = run_plan(session, op("motion.move_to", "far", target=far))
    message = run.messages()["far"]
    assert run.status is Status.FAILURE and "unreachable" in message and "1500.0) mm" in message
    assert "24 symmetric equivalents" in message
