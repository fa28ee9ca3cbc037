"""The suction tool: unholster, pick and place with vacuum, holster (scripted with moves)."""

from __future__ import annotations

from collections.abc import Callable

from capabilities.sim.cell import SimCell
from capabilities.sim.testing import distance, down_at, run
from engine.types import Pose


def _above(pose: Pose, dz: float) -> Pose:
    x, y, z = pose.position
    return Pose((x, y, z + dz), pose.orientation)


def _unholster(cell: SimCell) -> None:
    grasp = cell.suction.handle_grasp_pose()
    run(cell.gripper.open())
    run(cell.robot.move_pose_joint_space(_above(grasp, 0.1)))
    run(cell.robot.move_linear(grasp))
    run(cell.gripper.close())
    run(cell.robot.move_linear(_above(cell.robot.tcp_pose(), 0.15)))


def _holster(cell: SimCell) -> None:
    tip = cell.suction.holstered_tip_pose()
    run(cell.robot.move_pose_joint_space(_above(tip, 0.1)))
    run(cell.robot.move_linear(tip))
    run(cell.gripper.open())
    run(cell.robot.move_linear(_above(cell.robot.tcp_pose(), 0.1)))


def test_suction_round_trip(cell: SimCell, make_box: Callable[..., int]) -> None:
    suction, truth = cell.suction, cell.ground_truth
    plate = make_box((0.1, 0.1, 0.01), (0.55, 0.15), mass=0.1)
    gripper_tcp = cell.tcp_offset()

    _unholster(cell)
    assert suction.in_hand() and cell.gripper.is_holding()
    assert cell.tcp_offset() == cell.config.tcp_offsets["suction"] != gripper_tcp
    tool_tip = truth.suction_tool_pose()
    assert distance(tool_tip, cell.robot.tcp_pose()) < 0.005  # the TCP is the cup tip

    top = cell.table_top_z + 0.01
    run(cell.robot.move_linear(down_at(0.55, 0.15, top + 0.1)))
    run(cell.robot.move_linear(down_at(0.55, 0.15, top - 0.0005)))
    run(suction.suction_on())
    assert suction.has_part() and truth.suction_attached() == plate
    run(cell.robot.move_linear(down_at(0.55, 0.15, top + 0.1)))
    run(cell.robot.move_linear(down_at(0.6, -0.2, top + 0.1)))
    run(cell.robot.move_linear(down_at(0.6, -0.2, top + 0.001)))
    run(suction.suction_off())
    assert not suction.has_part()
    run(cell.robot.move_linear(down_at(0.6, -0.2, top + 0.1)))
    cell.wait_sim(0.3)
    x, y, _ = truth.body_pose(plate).position
    assert abs(x - 0.6) < 0.02 and abs(y + 0.2) < 0.02

    _holster(cell)
    assert not suction.in_hand() and cell.tcp_offset() == gripper_tcp
    cell.wait_sim(0.5)
    expected = cell.config.holster_pose.compose(Pose((0.0, 0.0, 0.01)))
    assert distance(truth.suction_tool_pose(), expected) < 0.005


def test_vacuum_without_the_tool_in_hand_is_refused(cell: SimCell) -> None:
    handle = cell.suction.suction_on()
    assert handle.wait(10) and handle.ok is False
    assert "not in the gripper" in handle.message
    assert not cell.suction.has_part()


def test_vacuum_on_with_nothing_at_the_cup_senses_no_part(cell: SimCell) -> None:
    _unholster(cell)
    handle = run(cell.suction.suction_on())
    assert "no part" in handle.message and not cell.suction.has_part()
    run(cell.suction.suction_off())
