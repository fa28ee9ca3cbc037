"""The selected waypoint's name, reference and numbers, edited in place.

Positions in mm and angles in degrees through the inspector's own editors (a pose as x, y,
z and roll, pitch, yaw; joints base to wrist); a relative waypoint's pose is the tool in
its object's (or marker's) frame. Each finished edit is emitted as the new waypoint; the
panel turns it into one document command.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from PySide6.QtCore import Signal
from PySide6.QtWidgets import (
    QFormLayout,
    QLabel,
    QLineEdit,
    QStackedWidget,
    QWidget,
)

from engine.types import JointConfig, Pose, Waypoint, WaypointFrame
from instructor_app.inspectors.geometry import JointConfigEditor, PoseEditor

__all__ = ["WaypointDetails"]

_FRAME_TEXT = {
    WaypointFrame.WORLD: "tool pose in the world",
    WaypointFrame.OBJECT: "tool pose relative to an object",
    WaypointFrame.MARKER: "tool pose relative to a marker",
    WaypointFrame.JOINTS: "joint angles",
}


class WaypointDetails(QWidget):
    """Name, frame, reference and numbers of one waypoint.

    Signals:
        edited(object): the waypoint as the user changed it (a new :class:`Waypoint`).
    """

    edited = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._waypoint: Waypoint | None = None
        self.name_edit = QLineEdit()
        self.name_edit.setObjectName("WaypointName")
        self.name_edit.setToolTip("The waypoint's name; nodes that use it follow a rename")
        self.name_edit.editingFinished.connect(self._name_finished)
        self.frame_label = QLabel()
        self.reference_edit = QLineEdit()
        self.reference_edit.setToolTip("The object class (e.g. cup) or marker id it is relative to")
        self.reference_edit.editingFinished.connect(self._reference_finished)
        self.pose_editor = PoseEditor()
        self.pose_editor.value_committed.connect(self._pose_committed)
        self.joints_editor = JointConfigEditor()
        self.joints_editor.value_committed.connect(self._joints_committed)
        self.numbers = QStackedWidget()
        self.numbers.addWidget(self.pose_editor)
        self.numbers.addWidget(self.joints_editor)
        form = QFormLayout(self)
        form.setContentsMargins(0, 0, 0, 0)
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        form.addRow("Name", self.name_edit)
        form.addRow("Frame", self.frame_label)
        form.addRow("Relative to", self.reference_edit)
        form.addRow(self.numbers)
        self.show_waypoint(None)

    def waypoint(self) -> Waypoint | None:
        return self._waypoint

    def show_waypoint(self, waypoint: Waypoint | None) -> None:
        """Show a waypoint (None: nothing selected, the fields are disabled)."""
        self._waypoint = waypoint
        self.setEnabled(waypoint is not None)
        if waypoint is None:
            self.name_edit.setText("")
            self.frame_label.setText("")
            self.reference_edit.setText("")
            return
        if not self.name_edit.hasFocus():
            self.name_edit.setText(waypoint.name)
        self.frame_label.setText(_FRAME_TEXT[waypoint.frame])
        relative = waypoint.frame in (WaypointFrame.OBJECT, WaypointFrame.MARKER)
        self.reference_edit.setEnabled(relative)
        self.reference_edit.setText(waypoint.reference if relative else "")
        if waypoint.frame is WaypointFrame.JOINTS:
            self.numbers.setCurrentWidget(self.joints_editor)
            self.joints_editor.set_value(waypoint.joints)
        else:
            self.numbers.setCurrentWidget(self.pose_editor)
            self.pose_editor.set_value(waypoint.pose)

    # ------------------------------------------------------------------ edits

    def _emit(self, **changes: Any) -> None:
        current = self._waypoint
        if current is None:
            return
        try:
            changed = dataclasses.replace(current, **changes)
        except ValueError:  # e.g. an empty reference: show the stored one again
            self.show_waypoint(current)
            return
        if changed != current:
            self.edited.emit(changed)

    def _name_finished(self) -> None:
        name = self.name_edit.text().strip()
        if name:
            self._emit(name=name)
        elif self._waypoint is not None:
            self.name_edit.setText(self._waypoint.name)

    def _reference_finished(self) -> None:
        self._emit(reference=self.reference_edit.text().strip())

    def _pose_committed(self, pose: Any) -> None:
        if isinstance(pose, Pose):
            self._emit(pose=pose)

    def _joints_committed(self, joints: Any) -> None:
        if isinstance(joints, JointConfig):
            self._emit(joints=joints)
