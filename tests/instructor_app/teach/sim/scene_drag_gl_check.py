"""Run by test_scene_drag.py in its own process on Xvfb's GL (QT_QPA_PLATFORM=xcb): in the
Instructor's window on the simulated cell, Shift-drag the tool gizmo of the 3D scene with the
mouse, let go, record the waypoint, preview it, and run a plan that goes there; then, with
the Move panel's Freedrive clicked on (a toggle on the simulated cell: one mouse cannot hold
it and drag), drag the tool with a plain left drag (no Shift), and click it off; prints one
JSON object of what it saw.
"""

from __future__ import annotations

import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
from PySide6.QtCore import QEventLoop, QPoint, QSettings, Qt, QTimer
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ParamType
from instructor_app.dialogs import Dialogs
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from instructor_app.settings import AppSettings


def wait_for(app: QApplication, done: object, seconds: float) -> bool:
    for _ in range(int(seconds * 50)):
        if done():  # type: ignore[operator]
            return True
        app.processEvents()
        QTest.qWait(20)
    return bool(done())  # type: ignore[operator]


def plain_drag(view: object, x: int, y: int, dx: int) -> None:
    """A left drag without a modifier from (x, y), ``dx`` px to the right, in steps."""
    none = Qt.KeyboardModifier.NoModifier
    QTest.mousePress(view, Qt.MouseButton.LeftButton, none, QPoint(x, y))  # type: ignore[call-overload]
    for k in range(1, 11):
        QTest.mouseMove(view, QPoint(x + dx * k // 10, y))  # type: ignore[call-overload]
        QTest.qWait(30)
    QTest.mouseRelease(view, Qt.MouseButton.LeftButton, none, QPoint(x + dx, y))  # type: ignore[call-overload]


def hand_guided(
    app: QApplication, window: MainWindow, out: dict[str, object], ended: list[str]
) -> None:
    """Without Freedrive a plain drag on the tool orbits the view; with Freedrive clicked on
    it moves the arm and the Move panel says so; a plain drag away from the tool still
    orbits; a second click turns Freedrive off.
    """
    scene, move = window.cell_views.scene3d, window.views.move
    view = scene.view
    arm = window.session.cell.interfaces()["arm"]
    start = arm.tcp_pose()
    wait_for(app, lambda: math.dist(scene._gizmo.position, start.position) < 1e-4, 5)
    azimuth = view.opts["azimuth"]
    gx, gy = view.to_screen(np.array(start.position))
    plain_drag(view, int(gx), int(gy), 40)
    QTest.qWait(300)
    out["plain_without_freedrive_mm"] = math.dist(arm.tcp_pose().position, start.position) * 1000
    out["plain_without_freedrive_orbits"] = view.opts["azimuth"] != azimuth
    out["hint_before"] = move.freedrive_hint.text()
    out["button_before"] = move.freedrive_button.text()
    QTest.mouseClick(move.freedrive_button, Qt.MouseButton.LeftButton)  # pressed and let go
    out["freedrive_on"] = wait_for(app, lambda: arm.freedrive_active(), 10)
    wait_for(app, lambda: move.freedrive_button.text() != out["button_before"], 5)
    out["button_on"] = move.freedrive_button.text()
    out["button_down"] = move.freedrive_button.isChecked()
    out["hint_held"] = (
        move.freedrive_hint.text() if wait_for(app, lambda: move.freedrive_hint.text(), 5) else ""
    )
    wait_for(app, lambda: view.hand_guiding, 5)
    start = arm.tcp_pose()
    gx, gy = view.to_screen(np.array(start.position))
    azimuth = view.opts["azimuth"]
    ended.clear()
    released: list[object] = []
    scene.gizmo_released.connect(released.append)
    plain_drag(view, int(gx), int(gy), 40)
    wait_for(app, lambda: "drag end:" in ended, 30)
    out["hand_moved_mm"] = math.dist(arm.tcp_pose().position, start.position) * 1000
    out["hand_at_release_mm"] = (
        math.dist(arm.tcp_pose().position, released[0].position) * 1000  # type: ignore[attr-defined]
        if released
        else None
    )
    out["hand_drag_kept_view"] = view.opts["azimuth"] == azimuth
    out["freedrive_still_on"] = arm.freedrive_active()
    here = arm.tcp_pose()
    plain_drag(view, 20, 20, 60)  # far from the tool: orbits
    QTest.qWait(300)
    out["away_orbits"] = view.opts["azimuth"] != azimuth
    out["away_kept_arm_mm"] = math.dist(arm.tcp_pose().position, here.position) * 1000
    out["freedrive_still_on_after_away"] = arm.freedrive_active()
    QTest.mouseClick(move.freedrive_button, Qt.MouseButton.LeftButton)  # the next click: off
    out["freedrive_released"] = wait_for(app, lambda: not arm.freedrive_active(), 10)
    wait_for(app, lambda: move.freedrive_hint.text() != out["hint_held"], 5)
    out["hint_after"] = move.freedrive_hint.text()
    out["button_up"] = not move.freedrive_button.isChecked()


def main() -> int:
    app = QApplication(sys.argv[:1])
    out: dict[str, object] = {}
    session = CellSession("sim", speed=None)
    session.open()
    scratch = Path(tempfile.mkdtemp())
    settings = AppSettings(QSettings(str(scratch / "s.ini"), QSettings.Format.IniFormat))
    window = MainWindow(session, settings, Dialogs(), scratch / "recovery")
    window.new_plan()
    window.resize(1600, 1000)
    window.show()
    QTest.qWaitForWindowExposed(window)
    window.docks["scene3d"].raise_()  # a tab below the canvas at this width: brought forward
    scene, teacher, panel = window.cell_views.scene3d, window.views.teacher, window.views.waypoints
    arm = session.cell.interfaces()["arm"]
    out["available"] = scene.available
    start = arm.tcp_pose()
    out["gizmo_on_tcp"] = wait_for(
        app,
        lambda: (
            scene._gizmo is not None and math.dist(scene._gizmo.position, start.position) < 1e-4
        ),
        5,
    )
    ended: list[str] = []
    teacher.finished.connect(lambda what, problem: ended.append(f"{what}:{problem}"))
    released: list[object] = []
    scene.gizmo_released.connect(released.append)
    view = scene.view
    gx, gy = view.to_screen(np.array(start.position))
    shift = Qt.KeyboardModifier.ShiftModifier
    QTest.mousePress(view, Qt.MouseButton.LeftButton, shift, QPoint(int(gx), int(gy)))
    for k in range(1, 11):  # the hand moves the ball 40 px to the right, in steps
        QTest.mouseMove(view, QPoint(int(gx) + 4 * k, int(gy)))
        QTest.qWait(30)
    QTest.mouseRelease(view, Qt.MouseButton.LeftButton, shift, QPoint(int(gx) + 40, int(gy)))
    out["drag_ended"] = wait_for(app, lambda: "drag end:" in ended, 30)
    target = released[0] if released else None
    out["moved_mm"] = math.dist(arm.tcp_pose().position, start.position) * 1000
    out["arm_at_release_mm"] = (
        math.dist(arm.tcp_pose().position, target.position) * 1000 if target else None  # type: ignore[attr-defined]
    )
    out["freedrive_off"] = not arm.freedrive_active()
    panel.frame_combo.setCurrentText("world")
    panel.name_field.setText("dragged")
    panel.record_button.click()
    dragged = window.document.plan.waypoints[0]
    panel.preview_button.setChecked(True)
    out["ghost_shown"] = wait_for(app, lambda: scene.ghost.items["base_link"].visible(), 10)
    hand_guided(app, window, out, ended)
    window.views.move.step_combo.setCurrentIndex(5)  # 50 mm
    window.views.move.jog_buttons["z+"].click()
    wait_for(app, lambda: ended[-1].startswith("jog"), 30)
    doc = window.document
    root = doc.add_node(NodeSpec(NodeKind.SEQUENCE, "go back"))
    params = {"target": Binding.fixed(dragged, ParamType.WAYPOINT)}
    doc.add_node(
        NodeSpec(NodeKind.OPERATION, "to dragged", op="motion.move_to", params=params), root
    )
    loop = QEventLoop()
    outcome: list[object] = []
    window.controller.run_finished.connect(lambda result: (outcome.append(result), loop.quit()))
    QTimer.singleShot(60_000, loop.quit)
    window.controller.run()
    loop.exec()
    out["run"] = outcome[0].status.value if outcome else "no end"  # type: ignore[attr-defined]
    out["after_run_mm"] = math.dist(arm.tcp_pose().position, dragged.pose.position) * 1000  # type: ignore[union-attr]
    window.shutdown()
    session.close()
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
