"""A breakpoint before a move on the simulated cell: the run pauses with the arm held where
the move before left it, and goes on to the end when continued.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import JointConfig, ParamType
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import click_node, make_window


def _move(name: str, target: tuple[float, ...]) -> NodeSpec:
    return NodeSpec(
        NodeKind.OPERATION,
        name=name,
        op="motion.move_joints",
        params={"target": Binding.fixed(JointConfig(target), ParamType.JOINTS)},
    )


def test_a_breakpoint_before_a_move_holds_the_arm_and_the_run_continues(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    robot = fast_sim.cell.interfaces()["arm"]
    home = robot.home_joints()
    turned = (home[0] + 0.5, *home[1:])
    moves = [_move("turn", turned), _move("turn back", tuple(home))]
    plan = PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=moves), name="turns")
    window = make_window(qtbot, fast_sim, tmp_path)
    window.document.load_text(dump_plan(plan), None)
    back = next(n.id for _, n in window.document.plan.walk() if n.name == "turn back")
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    click_node(qtbot, window, back)
    qtbot.keyClick(window.views.canvas.viewer, Qt.Key.Key_F9)
    controller = window.controller
    with qtbot.waitSignal(controller.run_paused, timeout=30000) as paused:
        controller.run()
    assert paused.args[0] == back
    assert not robot.is_moving()
    assert abs(robot.joint_positions()[0] - turned[0]) < 0.02  # where the first move left it
    assert window.views.canvas.status_of(back) is Status.IDLE  # not started
    with qtbot.waitSignal(controller.run_finished, timeout=30000) as finished:
        window.debug_actions.resume.trigger()
    assert finished.args[0].status is Status.SUCCESS
    assert abs(robot.joint_positions()[0] - home[0]) < 0.02
