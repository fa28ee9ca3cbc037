"""Run by test_scene_drag.py in its own process on Xvfb's GL (QT_QPA_PLATFORM=xcb): in the
Instructor's window on the simulated cell, Shift-drag the tool gizmo of the 3D scene with the
mouse, let go, record the waypoint, preview it, and run a plan that goes there; prints one
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
