"""The parallel gripper: open/close, the holding sensor, grasp-move-release of a box."""

from __future__ import annotations

from collections.abc import Callable

from capabilities.sim.cell import SimCell
from capabilities.sim.testing import down_at, run

APPROACH = 0.15


def test_closing_on_nothing_is_closed_but_not_holding(cell: SimCell) -> None:
    gripper = cell.gripper
    assert not gripper.is_closed() and gripper.gap() > 0.08
    run(gripper.close())
    assert gripper.is_closed() and not gripper.is_holding()
    assert gripper.gap() < 0.002
    run(gripper.open())
    assert not gripper.is_closed() and gripper.gap() > 0.084


def test_grasp_move_and_release_a_box_where_asked(
    cell: SimCell, make_box: Callable[..., int]
) -> None:
    robot, gripper, truth = cell.robot, cell.gripper, cell.ground_truth
    box = make_box((0.04, 0.04, 0.05), (0.5, 0.1))
    grasp_z = cell.table_top_z + 0.03
    run(robot.move_pose_joint_space(down_at(0.5, 0.1, APPROACH)))
    run(robot.move_linear(down_at(0.5, 0.1, grasp_z)))
    run(gripper.close())
    assert gripper.is_holding()
    assert 0.035 < gripper.gap() < 0.045
    assert truth.gripper_attached() == box
    run(robot.move_linear(down_at(0.5, 0.1, APPROACH)))
    run(robot.move_pose_joint_space(down_at(0.4, -0.2, APPROACH, yaw=0.7)))  # the box comes along
    assert truth.gripper_attached() == box
    run(robot.move_linear(down_at(0.4, -0.2, grasp_z + 0.002, yaw=0.7)))
    run(gripper.open())
    assert not gripper.is_holding() and truth.gripper_attached() is None
    run(robot.move_linear(down_at(0.4, -0.2, APPROACH)))
    cell.wait_sim(0.5)
    x, y, z = truth.body_pose(box).position
    assert abs(x - 0.4) < 0.02 and abs(y + 0.2) < 0.02
    assert abs(z - (cell.table_top_z + 0.025)) < 0.005  # resting on the table
