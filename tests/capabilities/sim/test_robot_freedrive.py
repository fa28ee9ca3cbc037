"""Freedrive: a push or a drag moves the arm; leaving freedrive holds it."""

from __future__ import annotations

from capabilities.sim.cell import SimCell
from capabilities.sim.testing import distance, down_at, run
from engine.types import Pose


def test_a_push_at_the_tcp_moves_the_arm_and_it_stays_when_released(cell: SimCell) -> None:
    robot = cell.robot
    before = robot.tcp_pose()
    robot.set_freedrive(True)
    assert robot.freedrive_active()
    robot.apply_tcp_wrench((0.0, 30.0, 0.0), duration=0.5)
    cell.wait_sim(1.0)
    pushed = robot.tcp_pose()
    assert pushed.position[1] - before.position[1] > 0.01  # moved along the push
    cell.wait_sim(0.5)
    assert distance(robot.tcp_pose(), pushed) < 5e-4  # damped: no drift once the push ends
    robot.set_freedrive(False)
    held = robot.tcp_pose()
    cell.wait_sim(0.5)
    assert distance(robot.tcp_pose(), held) < 5e-4


def test_drag_to_a_pose_moves_the_tcp_there(cell: SimCell) -> None:
    robot = cell.robot
    start = robot.tcp_pose()
    target = Pose(
        (start.position[0] + 0.05, start.position[1] - 0.04, start.position[2] + 0.03),
        start.orientation,
    )
    robot.set_freedrive(True)
    run(robot.freedrive_drag_to(target))
    cell.wait_sim(0.2)
    assert distance(robot.tcp_pose(), target) < 1e-3


def test_moves_are_refused_during_freedrive_and_allowed_after(cell: SimCell) -> None:
    robot = cell.robot
    robot.set_freedrive(True)
    refused = robot.move_pose_joint_space(down_at(0.5, 0.0, 0.2))
    assert refused.wait(10) and refused.ok is False and "freedrive" in refused.message
    robot.set_freedrive(False)
    assert not robot.freedrive_active()
    run(robot.move_pose_joint_space(down_at(0.5, 0.0, 0.2)))
    drag = robot.freedrive_drag_to(down_at(0.5, 0.0, 0.3))
    assert drag.wait(10) and drag.ok is False
