"""The Move panel on the simulated cell: a jog by step moves the tool by that step, a held
arrow moves until it is let go, joints jog one by one, the readout follows the arm.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from PySide6.QtCore import Qt

from instructor_app.panels.move import STEPS, MovePanel
from instructor_app.runtime.session import CellSession
from instructor_app.runtime.teach import RobotTeacher
from tests.instructor_app.gui_driver import choose
from tests.instructor_app.teach.held import hold_ready


@pytest.fixture
def panel(qtbot: Any, teacher: RobotTeacher) -> MovePanel:
    widget = MovePanel(teacher)
    qtbot.addWidget(widget)
    widget.show()
    return widget


def click_and_wait(qtbot: Any, panel: MovePanel, button: Any) -> tuple[str, str]:
    with qtbot.waitSignal(panel.teacher.finished, timeout=20_000) as blocker:
        qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    return tuple(blocker.args)  # type: ignore[return-value]


def step_label(metres: float) -> str:
    return next(label for label, m, _ in STEPS if m == metres)


@pytest.mark.parametrize("frame", ["Base", "Tool"])
def test_a_step_moves_the_tool_by_that_step(
    qtbot: Any, panel: MovePanel, fast_sim: CellSession, frame: str
) -> None:
    arm = fast_sim.cell.interfaces()["arm"]
    choose(qtbot, panel.step_combo, step_label(0.010))
    choose(qtbot, panel.frame_combo, frame)
    before = arm.tcp_pose()
    assert click_and_wait(qtbot, panel, panel.jog_buttons["z+"]) == (f"jog {frame.lower()} z", "")
    after = arm.tcp_pose()
    # In the base frame the tool rises along world z; in the tool frame it moves along its
    # own z, which points down at home (the tool looks at the table).
    moved = (
        before.inverse().compose(after).position
        if frame == "Tool"
        else tuple(a - b for a, b in zip(after.position, before.position, strict=True))
    )
    assert moved == pytest.approx((0.0, 0.0, 0.010), abs=5e-4)
    assert after.orientation == pytest.approx(before.orientation, abs=1e-3)
    qtbot.waitUntil(
        lambda: panel.pose_labels[2].text().strip() == f"{after.position[2] * 1000:.1f} mm"
    )


def test_a_turn_step_and_a_joint_step(qtbot: Any, panel: MovePanel, fast_sim: CellSession) -> None:
    arm = fast_sim.cell.interfaces()["arm"]
    choose(qtbot, panel.step_combo, step_label(0.005))
    before = arm.tcp_pose()
    assert click_and_wait(qtbot, panel, panel.jog_buttons["rz+"])[1] == ""
    after = arm.tcp_pose()
    turn = before.inverse().compose(after)
    assert after.position == pytest.approx(before.position, abs=5e-4)  # turned about the TCP
    assert 2 * math.degrees(math.acos(min(1.0, abs(turn.orientation[3])))) == pytest.approx(
        5, abs=0.2
    )
    q0 = arm.joint_positions()
    assert click_and_wait(qtbot, panel, panel.joint_buttons[(0, -1)]) == ("jog joint 1", "")
    q1 = arm.joint_positions()
    assert math.degrees(q1[0] - q0[0]) == pytest.approx(-5.0, abs=0.05)
    assert q1[1:] == pytest.approx(q0[1:], abs=1e-3)


def test_a_held_arrow_moves_until_let_go(
    qtbot: Any, panel: MovePanel, fast_sim: CellSession
) -> None:
    arm = fast_sim.cell.interfaces()["arm"]
    choose(qtbot, panel.step_combo, "while held")
    start = arm.tcp_pose().position
    button = panel.jog_buttons["y+"]
    hold_ready(qtbot, button)
    qtbot.mousePress(button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: arm.tcp_pose().position[1] - start[1] > 0.02, timeout=20_000)
    assert arm.is_moving()
    with qtbot.waitSignal(panel.teacher.finished, timeout=20_000) as blocker:
        qtbot.mouseRelease(button, Qt.MouseButton.LeftButton)
    assert blocker.args == ["jog base y", ""]
    qtbot.waitUntil(lambda: not arm.is_moving(), timeout=5_000)
    stopped = arm.tcp_pose().position
    fast_sim.cell.sim.wait_sim(0.5)
    assert arm.tcp_pose().position == pytest.approx(stopped, abs=1e-4)  # it stays stopped
    assert stopped[0] == pytest.approx(start[0], abs=1e-3)  # only along y
    assert stopped[2] == pytest.approx(start[2], abs=1e-3)
