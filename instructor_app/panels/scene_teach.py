"""Teaching in the 3D scene: drag the tool gizmo and the arm follows; preview waypoints.

Uses only the scene's public API (:class:`instructor_app.panels.scene3d.Scene3DPanel`):
``available``, ``set_gizmo(pose | None)``, ``set_hand_guiding(bool)``,
``show_ghost(joints | None)`` and the signals ``gizmo_dragged(Pose)`` and
``gizmo_released(Pose)``. The gizmo sits on the TCP while nobody drags it; a drag sends the
newest pose to the RobotTeacher (freedrive drag on the simulated cell, IK and joint moves
elsewhere), off the GUI thread. While Freedrive is on, a plain drag on the gizmo moves it
(Shift + drag at any time).
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QObject

from engine.types import Pose
from instructor_app.runtime.teach import ArmState, RobotTeacher

__all__ = ["SceneTeachLink"]


class SceneTeachLink(QObject):
    """Connects a 3D scene to the teacher and the waypoints panel.

    Args:
        scene: the 3D scene panel (nothing is connected when it has no OpenGL).
        teacher: moves the arm.
        waypoints: the waypoints panel (its Preview shows the scene's ghost arm).
    """

    def __init__(
        self, scene: Any, teacher: RobotTeacher, waypoints: Any, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self.scene = scene
        self.teacher = teacher
        self.dragging = False
        if not getattr(scene, "available", False):
            return
        scene.gizmo_dragged.connect(self._dragged)
        scene.gizmo_released.connect(self._released)
        teacher.state_changed.connect(self._state)
        waypoints.set_scene(scene)
        self._state(teacher.state)

    def _dragged(self, pose: object) -> None:
        if isinstance(pose, Pose):
            self.dragging = True
            self.teacher.drag_to(pose)

    def _released(self, pose: object) -> None:
        if isinstance(pose, Pose):
            self.teacher.drag_to(pose)
        self.teacher.end_drag()
        self.dragging = False

    def _state(self, state: object) -> None:
        self.scene.set_hand_guiding(isinstance(state, ArmState) and state.freedrive)
        if self.dragging:
            return  # the gizmo is where the hand is; the arm is on its way
        self.scene.set_gizmo(state.tcp if isinstance(state, ArmState) else None)
