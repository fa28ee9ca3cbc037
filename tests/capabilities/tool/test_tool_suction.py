"""tool: unholster, pick a plate with a smart waypoint, place it, holster."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import distance, down_at
from capabilities.world_model import Detection
from engine.status import Status
from engine.types import Pose, Waypoint, WaypointFrame
from tests.capabilities.motion.plans import DOWN, build, op, run_plan, seq, sim_steps

pytestmark = pytest.mark.sim

PLATE = "plate_4_holes"
THICKNESS = 0.005  # m
PLACE = (0.40, 0.0)  # free table space in the kitting scene with seed 0


@pytest.fixture
def session() -> Iterator[SimCellSession]:
    with SimCellSession("kitting", seed=0) as cell:
        yield cell


def _relative(name: str, z: float) -> Waypoint:
    return Waypoint(name, WaypointFrame.OBJECT, Pose((0.0, 0.0, z), DOWN), reference=PLATE)


def test_suction_round_trip_with_a_relative_waypoint(session: SimCellSession) -> None:
    plate = session.truth_pose(PLATE)  # stands in for perception: the test tells the world model
    session.world_model.replace("test", [Detection(PLATE, plate, 1.0, session.clock(), "test")])
    plan = seq(
        op("tool.unholster"),
        op("motion.move_to", "over plate", target=_relative("over plate", 0.1)),
        op(
            "motion.move_to",
            "on plate",
            target=_relative("on plate", THICKNESS - 0.0005),
            mode="linear",
        ),
        op("tool.suction_on"),
        op("tool.has_part"),
        op("motion.move_relative", "lift", dz=0.1),
        op("motion.move_to", "over place", target=down_at(*PLACE, 0.12, yaw=0.5)),
        op(
            "motion.move_to",
            "lower",
            target=down_at(*PLACE, THICKNESS + 0.001, yaw=0.5),
            mode="linear",
        ),
        op("tool.suction_off"),
        op("motion.move_relative", "clear", dz=0.1),
        op("tool.holster"),
    )
    run = run_plan(session, plan, timeout=120)
    assert run.status is Status.SUCCESS, run.failure()
    suction = session.sim.suction
    assert not suction.in_hand() and not session.sim.gripper.is_holding()
    session.sim.wait_sim(0.5)
    placed = session.truth_pose(PLATE)
    assert math.dist(placed.position[:2], PLACE) < 0.02 and abs(placed.position[2]) < 0.003
    back = session.sim.config.holster_pose.compose(Pose((0.0, 0.0, 0.01)))
    assert distance(session.ground_truth.suction_tool_pose(), back) < 0.005


def test_vacuum_without_the_tool_fails_and_holster_has_nothing_to_do(
    session: SimCellSession,
) -> None:
    run = run_plan(session, op("tool.suction_on", "on"))
    assert run.status is Status.FAILURE and "not in the gripper" in run.messages()["on"]
    run = run_plan(session, seq(op("tool.holster"), op("tool.has_part", "part")))
    assert run.status is Status.FAILURE and run.messages()["part"] == "false"
    assert run.statuses()["tool.holster"] is Status.SUCCESS


def test_halting_unholster_stops_the_arm(session: SimCellSession) -> None:
    arm = session.sim.robot
    tree = build(session, op("tool.unholster"))
    assert tree.tick() is Status.RUNNING
    moving = False
    for _ in sim_steps(session, 0.05, 3.0):
        assert tree.tick() is Status.RUNNING
        if arm.is_moving():
            moving = True
            break
    assert moving
    tree.reset()
    session.sim.wait_sim(0.3)
    assert max(abs(v) for v in arm.joint_velocities()) < 0.01
    assert not session.sim.suction.in_hand()
