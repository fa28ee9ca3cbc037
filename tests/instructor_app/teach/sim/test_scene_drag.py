"""Dragging the tool in the 3D scene on the simulated cell: the arm follows the gizmo, the
pose where the hand let go is recorded and a plan that uses it runs; Preview shows the
ghost arm at a waypoint. The scene here is a stand-in with the 3D panel's public API
(COORD-scene3d.md): its signals are what a drag on the gizmo emits.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QObject, Qt, Signal
from PySide6.QtWidgets import QApplication

from engine.status import Status
from engine.types import Pose
from instructor_app.panels.move import (
    DRAG_HINT,
    DRAG_HINT_OFF,
    FREEDRIVE_TOGGLE,
    FREEDRIVE_TOGGLE_ON,
)
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
        self.hand_guiding = False

    def set_hand_guiding(self, on: bool) -> None:
        self.hand_guiding = on

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
    gizmo = scene.gizmo  # the waitUntil above saw it set
    assert gizmo is not None
    assert gizmo.position == pytest.approx(start.position, abs=1e-4)
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


def test_on_the_simulated_cell_a_click_turns_freedrive_on_until_the_next_click(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    """One mouse cannot hold Freedrive and drag the tool: on the simulated cell a click turns
    it on and it stays on; a plain drag on the tool moves the arm; the next click, Esc, the
    cell changing or a run starting turn it off.
    """
    window = make_window(qtbot, fast_sim, tmp_path)
    window.new_plan()
    teacher, move = window.views.teacher, window.views.move
    arm = fast_sim.cell.interfaces()["arm"]
    scene = SceneStandIn()
    link = SceneTeachLink(scene, teacher, window.views.waypoints)
    button = move.freedrive_button
    assert button.isCheckable() and button.text() == FREEDRIVE_TOGGLE
    assert move.freedrive_hint.text() == DRAG_HINT_OFF

    def turn_on() -> None:
        with qtbot.waitSignal(teacher.finished, timeout=10_000) as blocker:
            qtbot.mouseClick(button, LEFT)  # pressed and let go
        assert blocker.args == ["freedrive", ""]
        qtbot.waitUntil(lambda: scene.hand_guiding and button.text() == FREEDRIVE_TOGGLE_ON)
        assert button.isChecked() and arm.freedrive_active()
        assert move.freedrive_hint.text() == DRAG_HINT

    panel = window.views.waypoints
    qtbot.waitUntil(lambda: scene.gizmo is not None)
    choose(qtbot, panel.frame_combo, "world")
    qtbot.keyClicks(panel.name_field, "start")
    qtbot.mouseClick(panel.record_button, LEFT)
    home = window.document.plan.waypoints[0]

    turn_on()
    fast_sim.cell.sim.wait_sim(0.5)
    assert arm.freedrive_active() and button.isChecked()  # on without a hand on the button

    start = arm.tcp_pose()
    path = [
        Pose(
            (start.position[0], start.position[1] + 0.01 * k, start.position[2]), start.orientation
        )
        for k in range(1, 6)
    ]
    for pose in path:  # what a plain drag on the tool emits while hand guiding is on
        scene.gizmo_dragged.emit(pose)
        qtbot.wait(20)
    with qtbot.waitSignal(
        teacher.finished, timeout=30_000, check_params_cb=lambda w, p: w == "drag end"
    ):
        scene.gizmo_released.emit(path[-1])
    assert arm.tcp_pose().position == pytest.approx(path[-1].position, abs=1e-3)
    assert arm.freedrive_active() and button.isChecked() and not link.dragging

    with qtbot.waitSignal(teacher.finished, timeout=10_000) as blocker:
        qtbot.mouseClick(button, LEFT)  # the next click: off
    assert blocker.args == ["freedrive off", ""]
    assert not arm.freedrive_active() and not button.isChecked()
    qtbot.waitUntil(lambda: not scene.hand_guiding and button.text() == FREEDRIVE_TOGGLE)
    assert move.freedrive_hint.text() == DRAG_HINT_OFF

    turn_on()  # Esc in the window turns it off
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow)
    qtbot.waitUntil(lambda: QApplication.focusWidget() is not None)
    with qtbot.waitSignal(teacher.finished, timeout=10_000) as blocker:
        qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Escape)
    assert blocker.args == ["freedrive off", ""]
    assert not arm.freedrive_active() and not button.isChecked()

    turn_on()  # the cell (re)opened: what the window does with its new registry
    with qtbot.waitSignal(teacher.finished, timeout=10_000) as blocker:
        window.views.set_registry(fast_sim.registry)
    assert blocker.args == ["freedrive off", ""]
    assert not arm.freedrive_active() and not button.isChecked() and button.isCheckable()

    turn_on()  # a run starting turns it off before the plan moves the arm
    search_insert(qtbot, window, "sequence", "sequence")
    node_id = search_insert(qtbot, window, "motion.move_to", "motion.move_to")
    set_value(qtbot, window, node_id, "target", home)
    assert run_to_end(qtbot, window, 60_000).status is Status.SUCCESS
    assert not arm.freedrive_active() and not button.isChecked()
    assert arm.tcp_pose().position == pytest.approx(start.position, abs=1e-3)


ROOT = Path(__file__).resolve().parents[4]


@pytest.mark.skipif(
    not os.environ.get("DISPLAY"), reason="needs an X display with GL (run under xvfb-run)"
)
def test_with_opengl_a_mouse_drag_of_the_gizmo_teaches_a_waypoint_a_plan_reaches() -> None:
    """The real 3D scene (Scene3DPanel) in the window, in its own process on Xvfb's GL."""
    env = {**os.environ, "QT_QPA_PLATFORM": "xcb", "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, str(Path(__file__).with_name("scene_drag_gl_check.py"))],
        capture_output=True, text=True, timeout=180, env=env, cwd=ROOT,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["available"] is True and out["gizmo_on_tcp"] is True
    assert out["drag_ended"] is True and out["freedrive_off"] is True
    assert out["moved_mm"] > 20  # the arm followed the hand...
    assert out["arm_at_release_mm"] < 1.0  # ...to where it let go
    assert out["ghost_shown"] is True
    assert out["run"] == "SUCCESS" and out["after_run_mm"] < 1.0
    # Freedrive clicked on (a toggle here): a plain drag on the tool moves the arm, and the
    # Move panel says how; the next click turns it off.
    assert out["plain_without_freedrive_mm"] < 1.0 and out["plain_without_freedrive_orbits"]
    assert out["hint_before"] == DRAG_HINT_OFF and out["button_before"] == FREEDRIVE_TOGGLE
    assert out["freedrive_on"] is True and out["button_down"] is True
    assert out["button_on"] == FREEDRIVE_TOGGLE_ON and out["hint_held"] == DRAG_HINT
    assert out["hand_moved_mm"] > 20 and out["hand_drag_kept_view"] is True
    assert out["hand_at_release_mm"] < 1.0
    assert out["freedrive_still_on"] is True  # the toggle holds it, not the drag
    assert out["away_orbits"] is True and out["away_kept_arm_mm"] < 1.0
    assert out["freedrive_still_on_after_away"] is True
    assert out["freedrive_released"] is True and out["button_up"] is True
    assert out["hint_after"] == DRAG_HINT_OFF
