"""motion: moves reach their targets, halting stops the arm, unreachable poses fail clearly."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import angle_between, distance, down_at
from engine.status import Status
from engine.types import JointConfig, Waypoint, WaypointFrame
from tests.capabilities.motion.plans import all_capabilities, build, op, run_plan, seq, sim_steps

pytestmark = pytest.mark.sim

MM = 1e-3
HALF_DEG = math.radians(0.5)
STILL = 0.01  # rad/s: a joint slower than this counts as standing


@pytest.fixture(scope="module")
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty") as cell:
        yield cell


def _arm(session: SimCellSession) -> object:
    return session.interfaces()["arm"]


def test_move_to_a_pose_in_joint_and_linear_mode_reaches_it(session: SimCellSession) -> None:
    first, second = down_at(0.45, -0.15, 0.20, yaw=0.4), down_at(0.50, 0.10, 0.15)
    plan = seq(
        op("motion.move_to", "joint", target=first),
        op("motion.current_pose", "p1", pose="$P1"),
        op("motion.move_to", "linear", target=second, mode="linear", speed=1.5),
        op("motion.current_pose", "p2", pose="$P2"),
        op("motion.is_stopped"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    for want, key in ((first, "P1"), (second, "P2")):
        got = run.value(key)
        assert distance(got, want) < MM and angle_between(got, want) < HALF_DEG


def test_world_waypoint_joints_home_and_relative_moves(session: SimCellSession) -> None:
    waypoint = Waypoint("above", WaypointFrame.WORLD, pose=down_at(0.4, 0.2, 0.25))
    plan = seq(
        op("motion.move_to", "to waypoint", target=waypoint),
        op("motion.move_relative", "up", dz=0.05),
        op("motion.move_relative", "tool x", dx=0.03, frame="tool"),
        op("motion.current_pose", "pose", pose="$P"),
        op("motion.current_joints", "joints", joints="$Q"),
        op("motion.go_home", "home"),
        op("motion.is_home", "at home"),
        op("motion.move_joints", "back", target="$Q"),
        op("motion.current_pose", "pose again", pose="$P2"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    # The tool points down, so its x axis is the world's x axis: +30 mm in x.
    want = down_at(0.43, 0.2, 0.30)
    assert distance(run.value("P"), want) < MM and angle_between(run.value("P"), want) < HALF_DEG
    assert isinstance(run.value("Q"), JointConfig)
    assert distance(run.value("P2"), want) < MM


def test_move_relative_tool_moves_along_the_tool_axis(session: SimCellSession) -> None:
    plan = seq(
        op("motion.move_to", "above", target=down_at(0.4, 0.2, 0.25)),
        op("motion.move_relative_tool", "approach", dz=0.05),
        op("motion.current_pose", "pose", pose="$P"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    # The tool points down: +50 mm along its z is 50 mm lower in the world.
    want = down_at(0.4, 0.2, 0.20)
    assert distance(run.value("P"), want) < MM and angle_between(run.value("P"), want) < HALF_DEG


def test_is_home_is_false_away_from_home(session: SimCellSession) -> None:
    run = run_plan(
        session,
        seq(op("motion.move_to", target=down_at(0.4, -0.2, 0.3)), op("motion.is_home")),
    )
    assert run.status is Status.FAILURE
    assert run.messages()["motion.is_home"] == "false"


def test_an_unreachable_pose_fails_with_the_pose_in_mm(session: SimCellSession) -> None:
    far = down_at(2.0, 0.0, 0.3)
    for mode in ("joint", "linear"):
        run = run_plan(session, op("motion.move_to", "far", target=far, mode=mode))
        assert run.status is Status.FAILURE
        message = run.messages()["far"]
        assert "unreachable" in message and "(2000.0, 0.0, 300.0) mm" in message
    run = run_plan(session, op("motion.move_relative", "down", dz=-3.0))
    assert run.status is Status.FAILURE and "unreachable" in run.messages()["down"]


def test_halting_a_running_move_stops_the_arm_quickly(session: SimCellSession) -> None:
    arm = session.sim.robot
    start = down_at(0.35, 0.3, 0.3)
    assert run_plan(session, op("motion.move_to", target=start)).status is Status.SUCCESS
    speeds: list[tuple[float, float]] = []  # (sim time, fastest joint), every physics step
    session.sim.add_step_hook(
        post=lambda t: speeds.append((t, max(abs(v) for v in arm.joint_velocities())))
    )
    tree = build(session, op("motion.move_to", "long move", target=down_at(0.35, -0.3, 0.3)))
    assert tree.tick() is Status.RUNNING
    for _ in sim_steps(session, 0.05, 0.4):
        assert tree.tick() is Status.RUNNING
    halted_at = session.clock()
    tree.reset()
    session.sim.wait_sim(0.5)
    after = [(t, v) for t, v in list(speeds) if t >= halted_at]
    assert after[0][1] > 0.3  # it was moving fast when halted
    moving = [t for t, v in after if v > STILL]
    assert moving[-1] - halted_at < 0.2
    assert distance(arm.tcp_pose(), start) > 0.05  # it had gone part of the way
    assert distance(arm.tcp_pose(), down_at(0.35, -0.3, 0.3)) > 0.05  # and no further


def test_speed_out_of_range_fails_with_a_message(session: SimCellSession) -> None:
    run = run_plan(session, op("motion.go_home", "home", speed=5.0))
    assert run.status is Status.FAILURE and "speed" in run.messages()["home"]


def test_stop_succeeds_when_nothing_moves(session: SimCellSession) -> None:
    plan = seq(op("motion.stop"), op("motion.is_stopped"), op("motion.is_moving", "moving"))
    run = run_plan(session, plan)
    assert run.status is Status.FAILURE and run.messages()["moving"] == "false"


def test_motion_is_unavailable_without_an_arm_and_says_why() -> None:
    registry = CapabilityRegistry(all_capabilities(), cell=NullCell())
    for op_id in ("motion.move_to", "gripper.close", "tool.unholster", "freedrive.start"):
        availability = registry.availability(op_id)
        assert not availability.available
        assert "needed by the" in availability.reason
    assert "arm" in registry.availability("motion.move_to").reason
    assert "suction" in registry.availability("tool.unholster").reason
    assert registry.availability("timing.wait_until").available
