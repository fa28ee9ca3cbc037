"""Dragging the tool in the 3D scene on the simulated cell: the arm follows the gizmo, the
pose where the hand let go is recorded and a plan that uses it runs; Preview shows the
ghost arm at a waypoint. The scene here is a stand-in with the 3D panel's public API
(COORD-scene3d.md): its signals are what a drag on the gizmo emits."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QObject, Qt, Signal

from engine.status import Status
from engine.types import Pose
from instructor_app.panels.scene_teach import SceneTeachLink
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import (
    choose,
    make_window,
    run_to_end,
    search_insert,
    set_value,
)

LEFT = Qt.MouseButton.LeftButton


class SceneStandIn(QObject):
    """The 3D panel's API as COORD-scene3d.md gives it."""

    gizmo_dragged = Signal(object)
    gizmo_released = Signal(object)
    available = True

    def __init__(self) -> None:
        super().__init__()
        self.gizmo: Pose | None = None
        self.ghosts: list[Any] = []

    def set_gizmo(self, pose: Pose | None) -> None:
        self.gizmo = pose

    def show_ghost(self, joints: Any) -> None:
        self.ghosts.append(joints)


def test_drag_the_tool_record_and_run(qtbot: Any, fast_sim: CellSession, tmp_path: Path) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    window.new_plan()
    teacher, panel = window.views.teacher, window.views.waypoints
    arm = fast_sim.cell.interfaces()["arm"]
    scene = SceneStandIn()
    link = SceneTeachLink(scene, teacher, panel)
    qtbot.waitUntil(lambda: scene.gizmo is not None)
    start = arm.tcp_pose()
    assert scene.gizmo.position == pytest.approx(start.position, abs=1e-4)
    # The hand drags the ball 8 cm along y and 4 cm down, in small steps, then lets go.
    path = [
        Pose(
            (start.position[0], start.position[1] + 0.01 * k, start.position[2] - 0.005 * k),
            start.orientation,
        )
        for k in range(1, 9)
    ]
    for pose in path:
        scene.gizmo_dragged.emit(pose)
        qtbot.wait(20)
    assert link.dragging
    with qtbot.waitSignal(
        teacher.finished, timeout=30_000, check_params_cb=lambda w, p: w == "drag end"
    ):
        scene.gizmo_released.emit(path[-1])
    assert arm.tcp_pose().position == pytest.approx(path[-1].position, abs=1e-3)
    assert not arm.freedrive_active() and not link.dragging
    qtbot.waitUntil(
        lambda: scene.gizmo.position == pytest.approx(arm.tcp_pose().position, abs=1e-4)
    )

    choose(qtbot, panel.frame_combo, "world")
    qtbot.keyClicks(panel.name_field, "dragged")
    qtbot.mouseClick(panel.record_button, LEFT)
    dragged = window.document.plan.waypoints[0]
    with qtbot.waitSignal(teacher.preview_ready, timeout=10_000) as blocker:
        qtbot.mouseClick(panel.preview_button, LEFT)
    assert blocker.args[0] == pytest.approx(arm.joint_positions(), abs=1e-3)
    assert scene.ghosts[-1] == blocker.args[0]

    choose(qtbot, window.views.move.step_combo, "50 mm / 15°")
    with qtbot.waitSignal(teacher.finished, timeout=30_000):
        qtbot.mouseClick(window.views.move.jog_buttons["x+"], LEFT)
    search_insert(qtbot, window, "sequence", "sequence")
    node_id = search_insert(qtbot, window, "motion.move_to", "motion.move_to")
    set_value(qtbot, window, node_id, "target", dragged)
    assert run_to_end(qtbot, window, 60_000).status is Status.SUCCESS
    assert arm.tcp_pose().position == pytest.approx(path[-1].position, abs=1e-3)
