"""The tending cell: the wire bender's scene, its seeded production and fault model, bad welds
that come apart and bad grasps that slip when a part is lifted (found by the gripper's
sensor), the bender's and the rack's markers, and occupancy watching the welding arm.
Ground truth is read here, in the tests, never by the code under test.
"""

from __future__ import annotations

import json
import math
import re
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.bullet import pybullet as p
from capabilities.markers import capability as markers_capability
from capabilities.markers.geometry import pose_errors
from capabilities.occupancy import capability as occupancy_capability
from capabilities.sim.bender import _spawn_piece
from capabilities.sim.bender_spec import FaultModel, parse_bender, plan_parts
from capabilities.sim.objects import SceneError
from capabilities.sim.scene import default_scene_path
from capabilities.sim.scene_spec import SceneFileError
from capabilities.sim.session import SimCameraDevice, SimCellSession
from capabilities.sim.testing import down_at, run
from engine.types import Pose, Region
from tests.capabilities.occupancy.helpers import run_op

SHAPES = {"wireform_u", "wireform_step"}
EXIT = (0.55, 0.28)  # the bender's exit in the world: its model's exit, its scene pose


def tending_scene(folder: Path, **bender: Any) -> Path:
    """A copy of ``resources/scenes/tending.json`` with its bender block changed."""
    data = json.loads(default_scene_path("tending").read_text(encoding="utf-8"))
    data["bender"].update(bender)
    path = folder / "tending_test.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


def _scene_data() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(default_scene_path("tending").read_text(encoding="utf-8"))
    return data


def _yaw(pose: Pose) -> float:
    x, y, z, w = pose.orientation
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


# --------------------------------------------------------------------------- without the sim


def test_the_plan_follows_the_seed_with_irregular_intervals_and_both_shapes() -> None:
    spec = parse_bender(_scene_data(), "tending.json")
    assert spec is not None and set(spec.shapes) == SHAPES
    first, again, other = (plan_parts(spec, s) for s in (3, 3, 4))
    assert first == again and first != other
    assert len(first) == spec.parts == 50
    gaps = np.diff([p.offset for p in first])
    assert gaps.min() >= 2 * spec.swing + spec.hold and gaps.std() > 1.0
    assert {p.shape for p in first} == SHAPES
    assert [p.name for p in first[:2]] == ["part_001", "part_002"]


def test_the_fault_rates_default_to_the_papers_and_a_run_can_set_them() -> None:
    spec = parse_bender(_scene_data(), "tending.json")
    assert spec is not None and spec.faults == FaultModel()
    parts = [p for seed in range(40) for p in plan_parts(spec, seed)]  # 2000 parts
    welds = sum(p.bad_weld for p in parts) / len(parts)
    grasps = sum(p.bad_grasp for p in parts) / len(parts)
    assert 0.01 < welds < 0.03 and 0.035 < grasps < 0.065  # Table I: 2 and ~5 per 100
    every = plan_parts(spec, 1, FaultModel(bad_weld=1.0, bad_grasp=0.0, interval_spread=0.0))
    assert all(p.bad_weld and not p.bad_grasp for p in every)
    assert np.allclose(np.diff([p.offset for p in every]), spec.interval)
    with pytest.raises(ValueError, match="bad_grasp"):
        FaultModel(bad_grasp=1.5)


@pytest.mark.parametrize(
    ("change", "where"),
    [
        ({"shapes": []}, "$.bender.shapes"),
        ({"faults": {"bad_weld": 2}}, "$.bender.faults.bad_weld"),
        ({"spread": {"z": 0.1}}, "$.bender.spread"),
        ({"interval": 1.0}, "$.bender.interval"),
    ],
)
def test_a_bad_bender_block_is_refused_with_its_json_path(change: dict, where: str) -> None:
    data = _scene_data()
    data["bender"].update(change)
    with pytest.raises(SceneFileError, match=re.escape(where)):
        parse_bender(data, "test.json")


# --------------------------------------------------------------------------- in the sim


@pytest.mark.parametrize(
    ("change", "message"),
    [({"fixture": "rack"}, "'tending_rack' is no wire bender"),
     ({"shapes": ["wireform_u", "cup"]}, "'cup' is no wireform")],
)  # fmt: skip
def test_a_bender_on_the_wrong_models_is_refused(
    tmp_path: Path, change: dict, message: str
) -> None:
    with pytest.raises(SceneError, match=re.escape(message)):
        SimCellSession(tending_scene(tmp_path, **change), seed=0)


def test_the_scene_loads_for_several_seeds_with_the_rack_elsewhere() -> None:
    poses = []
    for seed in (0, 1, 2, 0):
        with SimCellSession("tending", seed) as session:
            assert session.bender is not None
            bender, rack = session.truth_pose("bender"), session.truth_pose("rack")
            assert np.allclose(bender.position[:2], (0.8, 0.28), atol=1e-6)
            assert abs(abs(_yaw(bender)) - math.pi) < 1e-4
            x, y, _ = rack.position
            assert 0.44 <= x <= 0.56 and -0.28 <= y <= -0.16 and abs(_yaw(rack)) <= 0.5 + 1e-6
            poses.append((x, y, _yaw(rack)))
    assert poses[0] == pytest.approx(poses[3])  # same seed, same rack
    assert min(math.dist(a[:2], b[:2]) for a, b in [(poses[0], poses[1]), (poses[1], poses[2]),
                                                       (poses[0], poses[2])]) > 0.005  # fmt: skip


def test_parts_come_at_the_planned_irregular_times_in_both_shapes(tmp_path: Path) -> None:
    scene = tending_scene(tmp_path, parts=6, interval=3.0, swing=0.5, hold=0.3, first_at=[1, 1.5])
    with SimCellSession(scene, seed=5) as session:
        bender = session.bender
        assert bender is not None
        planned = bender.release_times()
        turns: list[float] = []  # the grasp's turn about z: the same for every shape
        for index, time in enumerate(planned):
            session.sim.wait_sim(time + 0.8 - session.clock())
            name = f"part_{index + 1:03d}"
            weld = _grasp(session, name)[0]  # its weld bead, where its grasp closes
            assert math.dist(weld.position[:2], EXIT) < 0.02  # landed with its weld at the exit
            assert session.truth_pose(name).position[2] < 0.002  # flat on the table
            turns.append(_yaw(weld))
            _take(session, name)
        produced = bender.produced()
        assert [e.part for e in produced] == [f"part_{i:03d}" for i in range(1, 7)]
        assert [e.time for e in produced] == pytest.approx(planned, abs=2 / 240)
        assert np.diff(planned).std() > 0.2  # irregular
        assert {e.shape for e in produced} == SHAPES
        apart = [abs(math.remainder(t - turns[0], 2 * math.pi)) for t in turns]
        assert max(apart) < 2 * 0.08 + 0.02  # the yaw spread, not the shape


def _grasp(session: SimCellSession, part: str) -> tuple[Pose, Pose]:
    """Where the gripper takes a part: its model's grasp on the part's (true) pose."""
    pose = session.truth_pose(part)
    grasp = session.scene.model(part).grasp()
    return pose.compose(grasp.pose), pose.compose(grasp.approach)


PARK = down_at(0.4, -0.05, 0.3)
FOLDED = (1.2, -2.2, 2.0, -1.4, -1.5708, 0.0)  # the arm folded over the robot's left


def _pick_first_part(session: SimCellSession) -> str:
    bender = session.bender
    assert bender is not None
    session.sim.wait_sim(bender.release_times()[0] + 1.0 - session.clock())
    part = bender.produced()[0].part
    at, above = _grasp(session, part)
    robot, gripper = session.sim.robot, session.sim.gripper
    run(robot.move_pose_joint_space(above))
    run(robot.move_linear(at))
    run(gripper.close())
    assert gripper.is_holding()  # every part is held when the fingers close on it
    run(robot.move_linear(above))
    session.sim.wait_sim(0.3)
    return part


@pytest.mark.parametrize(
    ("weld", "slip", "kind"), [(0.0, 0.0, None), (1.0, 0.0, "weld_broke"), (0.0, 1.0, "slipped")]
)
def test_a_lifted_part_is_held_unless_its_weld_or_its_grasp_is_bad(
    tmp_path: Path, weld: float, slip: float, kind: str | None
) -> None:
    faults = FaultModel(bad_weld=weld, bad_grasp=slip)
    scene = tending_scene(tmp_path, parts=1)  # no second part: the arm stays up
    with SimCellSession(scene, seed=3, faults=faults) as session:
        bender = session.bender
        assert bender is not None
        part = _pick_first_part(session)
        gripper = session.sim.gripper
        events = [e for e in bender.events() if e.kind != "released"]
        assert [e.kind for e in events] == ([kind] if kind else [])
        assert gripper.is_holding() is (kind is None)  # found by the gripper's sensor
        held = session.ground_truth.gripper_attached()  # a hold that is gone is forgotten
        assert (held is None) is (kind is not None)
        if kind == "weld_broke":
            assert part not in session.scene.objects  # it came apart into its pieces
            pieces = bender.pieces()
            assert len(pieces) == 2
            heights = [session.ground_truth.body_pose(b).position[2] for b in pieces]
            assert max(heights) < 0.02  # both fell back onto the table
        elif kind == "slipped":
            assert session.truth_pose(part).position[2] < 0.02  # whole, back on the table
        else:
            assert session.truth_pose(part).position[2] > 0.08  # up with the gripper
        run(gripper.open())


def _take(session: SimCellSession, name: str) -> None:
    """GROUND TRUTH: take a part out of the cell (as if it was carried away)."""
    session.sim.call(lambda client: session.scene.remove(client, name))


def test_both_shapes_can_be_picked_from_the_exit(tmp_path: Path) -> None:
    scene = tending_scene(tmp_path, parts=4, interval=12.0, first_at=[1.0, 1.5])
    faults = FaultModel(bad_weld=0.0, bad_grasp=0.0)
    with SimCellSession(scene, seed=5, faults=faults) as session:
        bender = session.bender
        assert bender is not None
        robot, gripper = session.sim.robot, session.sim.gripper
        todo = set(SHAPES)
        for planned, time in zip(bender.plan, bender.release_times(), strict=True):
            session.sim.wait_sim(max(0.0, time + 0.8 - session.clock()))
            if planned.shape not in todo:
                _take(session, planned.name)
                continue
            todo.discard(planned.shape)
            at, above = _grasp(session, planned.name)
            run(robot.move_pose_joint_space(above))
            run(robot.move_linear(at))
            run(gripper.close())
            run(robot.move_linear(above))
            assert gripper.is_holding(), planned.shape
            assert session.truth_pose(planned.name).position[2] > 0.08, planned.shape
            _take(session, planned.name)
            run(gripper.open())
            run(robot.move_pose_joint_space(PARK))  # out of the welding arm's way
        assert not todo


def test_the_markers_capability_finds_the_bender_and_the_rack() -> None:
    with SimCellSession("tending", seed=2) as session:
        # At home the arm hides the rack from the shoulder camera: fold it away first.
        run(session.sim.robot.move_joints(FOLDED, speed=3.0, accel=6.0))
        registry = CapabilityRegistry([markers_capability()], cell=session)
        outcome = run_op(registry, "markers.detect_markers", camera="shoulder")
        assert outcome.ok, outcome
        for name, model in (("bender", "wire_bender"), ("rack", "tending_rack")):
            found = session.world_model.best(model)
            assert found is not None, f"{model} not seen: {outcome.message}"
            truth = session.truth_pose(name)
            assert math.dist(found.pose.position, truth.position) < 0.01, name
            assert abs(math.remainder(_yaw(found.pose) - _yaw(truth), 2 * math.pi)) < 0.05, name


def test_occupancy_sees_the_welding_arm_swing_down(tmp_path: Path) -> None:
    # One part; the arm holds over the exit for 20 s (simulated), then rests for good.
    scene = tending_scene(tmp_path, parts=1, first_at=[1.0, 1.0], swing=0.5, hold=20.0,
                          interval=25.0)  # fmt: skip
    with SimCellSession(scene, seed=2, shoulder_size=(320, 240)) as session:
        registry = CapabilityRegistry([occupancy_capability()], cell=session)
        bender = session.bender
        assert bender is not None
        # The region around the arm's release position: over the exit, at the bender's top.
        region = Region((0.6, 0.28, 0.235), 0.05)

        def occupied() -> bool:
            outcome = run_op(registry, "occupancy.is_occupied", region=region, max_age=0.0)
            assert "camera" not in outcome.message, outcome
            return outcome.ok

        release = bender.release_times()[0]
        session.sim.wait_sim(release + 0.2 - session.clock())
        assert occupied()  # the arm holds over the exit
        session.sim.wait_sim(release + 20.0 + 0.5 + 0.3 - session.clock())
        assert not occupied()  # the arm is back up, out of the region
        assert bender.produced()[0].part in session.scene.objects  # the part it let go


def test_the_shoulder_camera_is_calibrated_on_the_benders_markers(tmp_path: Path) -> None:
    data = _scene_data()
    data["markers"] = []  # no table markers: the bender's are the only ones of known pose
    scene = tmp_path / "tending_no_table_markers.json"
    scene.write_text(json.dumps(data), encoding="utf-8")
    with SimCellSession(scene, seed=1) as session:
        layout = session.scene_layout()["fixed_markers"]
        assert set(layout) == {30, 31}  # the rack moves between runs: its markers are not
        camera = session.cameras["shoulder"]
        assert isinstance(camera, SimCameraDevice)  # a rendered camera: it can be displaced
        nominal = camera.extrinsics()
        turn = Pose((0.0, 0.0, 0.0), (0.0, math.sin(0.02), 0.0, math.cos(0.02)))  # 2.3 deg
        true_pose = Pose(tuple(np.add(nominal.position, (0.02, -0.015, 0.01))),
                         turn.compose(Pose((0.0, 0.0, 0.0), nominal.orientation)).orientation)  # fmt: skip
        camera.displace_for_test(true_pose)
        registry = CapabilityRegistry([markers_capability()], cell=session)
        outcome = run_op(registry, "markers.calibrate_camera", camera="shoulder")
        assert outcome.ok, outcome
        position_error, angle = pose_errors(camera.extrinsics(), true_pose)
        # Displaced by 27 mm and 2.3 deg; the bender's two markers, 1.3 m away and close
        # together, leave the distance along the view ray least constrained (measured: 13 mm
        # and 0.46 deg after).
        assert position_error < 0.02 and math.degrees(angle) < 1.0


def test_the_bender_waits_for_the_run_when_asked(tmp_path: Path) -> None:
    scene = tending_scene(tmp_path, parts=1, first_at=[1.0, 1.0])
    with SimCellSession(scene, seed=0, start_actors=False) as session:
        bender = session.bender
        assert bender is not None
        session.sim.wait_sim(3.0)
        assert bender.start_time is None and not bender.events()  # nothing before the start
        session.start_actors()
        started = bender.start_time
        assert started is not None and started >= 3.0
        session.sim.wait_sim(1.5)
        assert [e.time for e in bender.produced()] == pytest.approx([started + 1.0], abs=2 / 240)


def _heights(session: SimCellSession, body: int) -> tuple[float, float]:
    """GROUND TRUTH: the lowest and highest z of a body's collision shape."""

    def aabb(client: int) -> tuple[float, float]:
        low, high = p.getAABB(body, physicsClientId=client)
        return float(low[2]), float(high[2])

    return session.sim.call(aabb)


def _remove(body: int, client: int) -> None:
    p.removeBody(body, physicsClientId=client)


def _tilt(pose: Pose) -> float:
    """How far a body's z axis leans from the vertical (rad)."""
    x, y, _, _ = pose.orientation
    return 2 * math.asin(min(1.0, math.hypot(x, y)))


def test_the_pieces_of_a_broken_weld_rest_flat_on_the_table_and_the_scrap_bin_floor(
    tmp_path: Path,
) -> None:
    scene = tending_scene(tmp_path, parts=1, first_at=[300.0, 300.0])  # no part meanwhile
    with SimCellSession(scene, seed=3) as session:
        top = session.scene.table_top_z
        scrap = session.truth_pose("scrap").position
        floor = scrap[2] + session.scene.model("scrap").extra["tote"]["floor"]
        spots = {(0.33, 0.12): top, (0.68, 0.05): top, scrap[:2]: floor}
        dropped: list[tuple[int, float]] = []
        for shape in sorted(SHAPES):
            model = session.scene.library.get(shape)
            for boxes in model.extra["weld"]["pieces"]:
                middle = np.mean([model.collision.boxes[b].position for b in boxes], axis=0)
                for (x, y), surface in spots.items():  # the piece's middle over the spot
                    at = (x - middle[0], y - middle[1], surface + 0.02)
                    frame = Pose(at, (0.0, 0.0, 0.0, 1.0))

                    def spawn(client: int, b: list[int] = boxes, f: Pose = frame,
                              m: Any = model) -> int:  # fmt: skip
                        return _spawn_piece(client, m, b, f)

                    dropped.append((session.sim.call(spawn), surface))
                session.sim.wait_sim(1.0)
                for body, surface in dropped:  # a piece lies on its 8 mm wire: 0 to 8 mm up
                    low, high = _heights(session, body)
                    assert surface - 0.002 < low and high < surface + 0.010, (shape, boxes)
                    assert _tilt(session.ground_truth.body_pose(body)) < math.radians(3)
                    session.sim.call(partial(_remove, body))
                dropped.clear()
