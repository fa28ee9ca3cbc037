"""moveJ, moveL, stop, cancel and refusals of the simulated UR5."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from capabilities.motion.jog import Jogger
from capabilities.robot.commands import CommandHandle
from capabilities.sim.cell import SimCell
from capabilities.sim.testing import angle_between, distance, down_at, run
from engine.types import Pose

TOL_M = 1e-3
TOL_RAD = math.radians(0.5)


def test_move_joints_reaches_the_target(cell: SimCell) -> None:
    q = list(cell.robot.home_joints())
    q[0] += 0.6
    q[1] += 0.3
    q[4] -= 0.4
    run(cell.robot.move_joints(q))
    want = cell.robot.forward_kinematics(q)
    assert distance(cell.robot.tcp_pose(), want) < TOL_M
    assert angle_between(cell.robot.tcp_pose(), want) < TOL_RAD
    assert not cell.robot.is_moving()


def test_move_linear_reaches_the_target_on_a_straight_line(cell: SimCell) -> None:
    robot = cell.robot
    run(robot.move_pose_joint_space(down_at(0.45, 0.25, 0.25)))
    start = robot.tcp_pose()
    target = down_at(0.6, -0.1, 0.1, yaw=0.5)
    samples: list[tuple[float, ...]] = []

    def record(_t: float) -> None:
        samples.append(robot.tcp_pose().position)

    cell.add_step_hook(post=record)
    run(robot.move_linear(target, speed=0.3))
    cell.remove_step_hook(post=record)  # else the list grows while it is read below
    assert distance(robot.tcp_pose(), target) < TOL_M
    assert angle_between(robot.tcp_pose(), target) < TOL_RAD
    a, b = np.array(start.position), np.array(target.position)
    direction = (b - a) / np.linalg.norm(b - a)
    deviations = [
        np.linalg.norm((p - a) - np.dot(p - a, direction) * direction)
        for p in map(np.array, samples)
    ]
    assert len(samples) > 100
    assert max(deviations) < 3e-3


def test_stop_halts_the_arm_within_a_fifth_of_a_second(cell: SimCell) -> None:
    q = list(cell.robot.home_joints())
    q[0] += 2.5
    move = cell.robot.move_joints(q, speed=1.05, accel=1.4)
    cell.wait_sim(1.5)  # well into the constant-speed phase
    assert cell.robot.is_moving()
    times: dict[str, float] = {}

    def stop_now(_client: int) -> CommandHandle:
        times["asked"] = cell.time()
        handle = cell.robot.stop()
        # Registered here, on the physics thread, before the stop can finish.
        handle.add_done_callback(lambda _h: times.update(stopped=cell.time()))
        return handle

    stop = cell.call(stop_now)
    run(stop)
    assert move.done() and move.ok is False and "stopped" in move.message
    assert times["stopped"] - times["asked"] <= 0.2
    cell.wait_sim(0.05)
    assert max(abs(v) for v in cell.robot.joint_velocities()) < 0.02


def test_cancel_stops_the_move_and_fails_its_handle(cell: SimCell) -> None:
    q = list(cell.robot.home_joints())
    q[0] -= 2.0
    move = cell.robot.move_joints(q)
    cell.wait_sim(0.8)
    move.cancel()
    move.cancel()  # idempotent
    assert move.wait(10)
    assert move.ok is False and "cancelled" in move.message
    cell.wait_sim(0.2)
    assert not cell.robot.is_moving()
    assert abs(cell.robot.joint_positions()[0] - q[0]) > 0.5


def test_unreachable_pose_gives_a_failed_handle_with_the_pose_in_mm(cell: SimCell) -> None:
    far = Pose((1.5, 0.2, 0.3), (1.0, 0.0, 0.0, 0.0))
    for handle in (cell.robot.move_linear(far), cell.robot.move_pose_joint_space(far)):
        assert handle.done() and handle.ok is False
        assert "unreachable" in handle.message
        assert "1500.0" in handle.message and "mm" in handle.message
    bad = cell.robot.move_joints([0.0, 0.0, 4.0, 0.0, 0.0, 0.0])
    assert bad.ok is False and "unreachable" in bad.message


def test_move_linear_through_the_base_singularity_fails_with_a_clear_message(cell: SimCell) -> None:
    run(cell.robot.move_pose_joint_space(down_at(0.4, 0.0, 0.3)))
    handle = cell.robot.move_linear(down_at(-0.4, 0.0, 0.3))
    assert handle.wait(30)
    assert handle.ok is False
    assert "unreachable" in handle.message or "branch flip" in handle.message


def test_a_jog_blocked_by_an_object_holds_where_it_stopped(
    cell: SimCell, make_box: Callable[..., int]
) -> None:
    # Issue 26: the arm went on pressing towards the target it could not reach, with its
    # full joint torques, and crept as what held it back gave way.
    robot = cell.robot
    top = cell.table_top_z
    run(robot.move_pose_joint_space(down_at(0.5, 0.1, top + 0.15)))
    make_box((0.25, 0.25, 0.05), (0.615, 0.1), mass=1.0)  # its edge under the tool
    jog = Jogger(robot).step("base", "z", -0.15, 0.2)
    assert jog.wait(60)
    assert jog.ok is False and "blocked" in jog.message
    assert robot.protective_stop() is None  # a movable object is no collision
    stopped = robot.tcp_pose()
    cell.wait_sim(60.0)
    assert distance(robot.tcp_pose(), stopped) < 1e-3
