"""The Move panel on the UR backend (ur_rtde against the loopback emulator): the same panel,
through the backend Protocols only. Freedrive held maps to freedriveMode (PolyScope 5.10+)
or teachMode (3.15), and a jog step moves the reported TCP by the step.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtCore import Qt

from capabilities.base import CapabilityRegistry
from instructor_app.panels.move import FREEDRIVE_HELD, FREEDRIVE_ON, MovePanel
from instructor_app.runtime.teach import RobotTeacher
from tests.capabilities.ur.conftest import connect, start_emulator  # noqa: F401 (fixtures)
from tests.capabilities.ur.emulators import wait_for
from tests.instructor_app.gui_driver import choose
from tests.instructor_app.teach.held import hold_ready
from tests.instructor_app.teach.test_waypoints_teach import FakeCell

LEFT = Qt.MouseButton.LeftButton


@pytest.fixture
def ur_panel(qtbot: Any, request: Any, start_emulator: Any, connect: Any) -> Iterator[Any]:  # noqa: F811
    emulator = start_emulator(request.param)
    _, arm = connect(emulator)
    teacher = RobotTeacher(CapabilityRegistry([], cell=FakeCell({"arm": arm, "freedrive": arm})))
    panel = MovePanel(teacher)
    qtbot.addWidget(panel)
    panel.show()
    yield panel, arm, emulator
    teacher.shutdown()


@pytest.mark.parametrize("ur_panel", ["5.12", "3.15"], indirect=True)
def test_freedrive_held_and_a_jog_step_on_the_ur_backend(qtbot: Any, ur_panel: Any) -> None:
    panel, arm, emulator = ur_panel
    qtbot.waitUntil(lambda: panel.pose_labels[2].text() != "—", timeout=10_000)
    # A real arm: held, as the pendant's button (no toggle that could be left on).
    assert not panel.freedrive_button.isCheckable()
    assert panel.freedrive_button.text() == FREEDRIVE_HELD and panel.freedrive_hint.text() == ""
    hold_ready(qtbot, panel.freedrive_button)
    qtbot.mousePress(panel.freedrive_button, LEFT)
    assert wait_for(lambda: emulator.state()["freedrive"] is True)
    qtbot.waitUntil(lambda: panel.freedrive_button.text() == FREEDRIVE_ON)
    with qtbot.waitSignal(panel.teacher.finished, timeout=10_000) as blocker:
        qtbot.mouseRelease(panel.freedrive_button, LEFT)
    assert blocker.args == ["freedrive off", ""]
    assert wait_for(lambda: emulator.state()["freedrive"] is False)
    qtbot.waitUntil(lambda: panel.freedrive_button.text() == FREEDRIVE_HELD)
    assert not panel.freedrive_button.isChecked()
    choose(qtbot, panel.step_combo, "10 mm / 10°")
    before = arm.tcp_pose().position
    with qtbot.waitSignal(panel.teacher.finished, timeout=30_000) as blocker:
        qtbot.mouseClick(panel.jog_buttons["z+"], LEFT)
    assert blocker.args == ["jog base z", ""]
    after = arm.tcp_pose().position
    assert after[2] - before[2] == pytest.approx(0.010, abs=0.002)
    assert after[:2] == pytest.approx(before[:2], abs=0.002)
