"""Run by test_scene3d.py in its own process on Xvfb's GL (QT_QPA_PLATFORM=xcb): drives the
3D scene on the simulated cell and prints one JSON object of what it saw.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from capabilities.geometry import pose_to_matrix
from capabilities.robot_body import RobotBody, robot_base_from_arm
from capabilities.sim.session import SimCellSession
from capabilities.world_model import Detection
from engine.types import Pose, Region, Waypoint
from instructor_app.panels.scene3d import IDLE_REFRESH_MS, REFRESH_MS, Scene3DPanel


def _wait_until(condition: Callable[[], bool], timeout_ms: int = 20000) -> bool:
    waited = 0
    while not condition() and waited < timeout_ms:
        QTest.qWait(20)
        waited += 20
    return condition()


def _idle_and_moving(panel: Scene3DPanel, cell: SimCellSession) -> dict[str, object]:
    """Nothing changes: the panel looks for changes slowly and draws nothing; the arm moves:
    it draws again at the quick rate (issue 26).
    """
    out: dict[str, object] = {}
    out["went_slow"] = _wait_until(lambda: panel.refresh_interval_ms == IDLE_REFRESH_MS)
    drawn, ticks = panel.frames_drawn, panel._tick
    out["idle_ticks"] = _wait_until(lambda: panel._tick >= ticks + 8) and panel._tick - ticks
    out["idle_frames"] = panel.frames_drawn - drawn
    q = cell.sim.robot.joint_positions()
    handle = cell.sim.robot.move_joints((q[0] + 0.5, *q[1:]), speed=0.3)
    out["drew_when_moving"] = _wait_until(lambda: panel.frames_drawn > drawn + 3)
    out["quick_when_moving"] = panel.refresh_interval_ms == REFRESH_MS or bool(handle.done())
    handle.wait(30.0)
    return out


def _labels_of_close_objects(panel: Scene3DPanel, cell: SimCellSession) -> dict[str, object]:
    """Two objects recognised 2 cm apart: their labels' screen rectangles (issue 26)."""
    near = [
        Detection("kit_bin", Pose((0.5, 0.1, 0.02)), 0.88, 0.0, "check"),
        Detection("plate_8_holes", Pose((0.52, 0.1, 0.02)), 1.0, 0.0, "check"),
    ]
    cell.interfaces()["world"].replace("check", near)
    wanted = {"kit_bin 88%", "plate_8_holes 100%"}
    _wait_until(lambda: wanted <= {text for text, _ in panel.label_rects()})
    return {"label_rects": [[text, list(rect)] for text, rect in panel.label_rects()]}


def main() -> int:
    app = QApplication(sys.argv[:1])
    out: dict[str, object] = {}
    with SimCellSession("cup_to_bin", seed=0) as cell:
        panel = Scene3DPanel()
        out["available"] = panel.available
        panel.resize(800, 600)
        panel.set_cell(cell)
        panel.set_regions([("REGION", Region((0.55, 0.0, 0.05), 0.08))])
        panel.set_waypoints([Waypoint("above", pose=Pose((0.5, 0.2, 0.3)))])
        panel.show()
        QTest.qWaitForWindowExposed(panel)
        for _ in range(20):
            app.processEvents()
            QTest.qWait(30)
        q = cell.sim.robot.joint_positions()
        frames = RobotBody(robot_base_from_arm(cell.sim.robot)).link_matrices(q)
        drawn = panel.robot.items["forearm_link"].transform()
        out["forearm_matches_fk"] = bool(
            np.allclose(np.array(drawn.data()).reshape(4, 4).T, frames[3], atol=1e-5)
        )
        out["frames_drawn"] = panel.frames_drawn
        view = panel.view
        picked: list[object] = []
        regions: list[object] = []
        gizmo: list[object] = []
        panel.point_picked.connect(picked.append)
        panel.region_drawn.connect(regions.append)
        panel.gizmo_released.connect(gizmo.append)
        # A click where the table top (z = 0) shows: project a table point to the screen.
        table_point = np.array([0.6, -0.2, 0.0])
        x, y = view.to_screen(table_point)
        QTest.mouseClick(view, Qt.MouseButton.LeftButton, pos=QPoint(int(x), int(y)))
        out["picked"] = [list(p) for p in picked]
        out["table_point"] = table_point.tolist()
        panel.region_button.setChecked(True)
        QTest.mousePress(view, Qt.MouseButton.LeftButton, pos=QPoint(int(x), int(y)))
        QTest.mouseMove(view, QPoint(int(x) + 20, int(y)))
        QTest.mouseMove(view, QPoint(int(x) + 40, int(y)))
        QTest.mouseRelease(view, Qt.MouseButton.LeftButton, pos=QPoint(int(x) + 40, int(y)))
        out["regions"] = [[list(r.center), r.radius] for r in regions]
        panel.region_button.setChecked(False)
        tcp = cell.sim.robot.tcp_pose()
        panel.set_gizmo(tcp)
        gx, gy = view.to_screen(np.array(tcp.position))
        shift = Qt.KeyboardModifier.ShiftModifier
        QTest.mousePress(view, Qt.MouseButton.LeftButton, shift, QPoint(int(gx), int(gy)))
        QTest.mouseMove(view, QPoint(int(gx) + 30, int(gy) - 10))
        QTest.mouseRelease(
            view, Qt.MouseButton.LeftButton, shift, QPoint(int(gx) + 30, int(gy) - 10)
        )
        out["gizmo_moved_by"] = (
            float(np.linalg.norm(np.subtract(gizmo[0].position, tcp.position))) if gizmo else None
        )
        out["gizmo_kept_orientation"] = bool(gizmo) and np.allclose(
            pose_to_matrix(gizmo[0])[:3, :3], pose_to_matrix(tcp)[:3, :3]
        )
        panel.show_ghost([0.0, -1.2, 1.0, -1.4, -1.57, 0.0])
        out["ghost_visible"] = panel.ghost.items["base_link"].visible()
        panel.show_ghost(None)
        out["ghost_hidden"] = not panel.ghost.items["base_link"].visible()
        out.update(_idle_and_moving(panel, cell))
        out.update(_labels_of_close_objects(panel, cell))
        panel.stop()
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
