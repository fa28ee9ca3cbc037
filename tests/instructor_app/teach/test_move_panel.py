"""The Move panel without a robot, with an arm that cannot be hand guided, and while a plan
runs: its buttons say why they are off; the readout follows the arm.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest

from capabilities.base import CapabilityRegistry
from engine.types import Pose
from instructor_app.panels.move import MovePanel
from instructor_app.runtime.teach import RobotTeacher
from tests.instructor_app.teach.test_waypoints_teach import FakeArm, FakeCell


@pytest.fixture
def arm() -> FakeArm:
    return FakeArm()


def panel_on(qtbot: Any, parts: dict[str, Any]) -> Iterator[MovePanel]:
    teacher = RobotTeacher(CapabilityRegistry([], cell=FakeCell(parts)), poll_ms=10)
    widget = MovePanel(teacher)
    qtbot.addWidget(widget)
    yield widget
    teacher.shutdown()


@pytest.fixture
def no_robot(qtbot: Any) -> Iterator[MovePanel]:
    yield from panel_on(qtbot, {})


@pytest.fixture
def arm_only(qtbot: Any, arm: FakeArm) -> Iterator[MovePanel]:
    yield from panel_on(qtbot, {"arm": arm})


def test_without_a_robot_nothing_moves_and_the_panel_says_why(no_robot: MovePanel) -> None:
    assert not any(b.isEnabled() for b in no_robot.jog_buttons.values())
    assert not no_robot.freedrive_button.isEnabled()
    assert no_robot.status_label.text() == "Cannot move the robot: this cell has no arm."
    assert {label.text() for label in no_robot.pose_labels} == {"—"}
    assert not no_robot.teacher.jog_step("base", "z", 0.01)


def test_the_readout_follows_the_arm_and_a_run_takes_the_robot(
    qtbot: Any, arm_only: MovePanel, arm: FakeArm
) -> None:
    qtbot.waitUntil(lambda: arm_only.pose_labels[0].text() == "500.0 mm")
    assert [label.text() for label in arm_only.pose_labels[3:]] == ["180.0 °", "0.0 °", "0.0 °"]
    assert arm_only.joint_labels[0].text() == f"{math.degrees(0.1):.2f} °"
    arm.tool = Pose((0.25, 0.1, 0.3), arm.tool.orientation)
    qtbot.waitUntil(lambda: arm_only.pose_labels[0].text() == "250.0 mm")
    assert not arm_only.freedrive_button.isEnabled()  # this arm has no hand guiding
    assert "no freedrive" in arm_only.freedrive_button.toolTip()
    assert all(b.isEnabled() for b in arm_only.jog_buttons.values())
    arm_only.teacher.set_run_active(True)
    assert not any(b.isEnabled() for b in arm_only.jog_buttons.values())
    assert arm_only.status_label.text() == "Cannot move the robot: a plan is running."
    arm_only.teacher.set_run_active(False)
    assert all(b.isEnabled() for b in arm_only.jog_buttons.values())
