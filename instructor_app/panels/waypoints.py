"""The plan's waypoints (``PlanSpec.waypoints``): the list the inspector's waypoint fields offer.

A worker teaches a waypoint by moving the arm (freedrive) and pressing Record: the panel
reads the arm's measured joints or tool pose from the cell, or, for a "smart waypoint", the
tool pose in the frame of an object the cell has seen. Waypoints taught earlier come in from
a waypoint file (``*.waypoints.json``, :class:`capabilities.waypoints.WaypointLibrary`).
Every change of the list is one document command (``set_plan_field("waypoints", ...)``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from PySide6.QtCore import Signal
from PySide6.QtWidgets import (
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QLineEdit,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from capabilities.waypoints import WaypointFileError, WaypointLibrary
from engine.types import JointConfig, Waypoint, WaypointFrame
from instructor_app.document import PlanDocument

__all__ = ["WaypointsPanel", "WAYPOINT_FILTER", "PathAsker"]

WAYPOINT_FILTER = "CoSTAR waypoints (*.waypoints.json);;JSON files (*.json);;All files (*)"
RECORD_FRAMES = ("joints", "world", "object")

PathAsker = Callable[[QWidget], str]


def _ask_waypoint_file(parent: QWidget) -> str:
    return QFileDialog.getOpenFileName(parent, "Import waypoints", "", WAYPOINT_FILTER)[0]


def _describe(waypoint: Waypoint) -> str:
    where = f" of {waypoint.reference}" if waypoint.reference else ""
    return f"{waypoint.name} ({waypoint.frame.value}{where})"


class WaypointsPanel(QWidget):
    """Lists, records, imports and removes the plan's waypoints.

    Args:
        document: the plan being edited.
        registry: the cell's registry; its cell's ``arm`` interface is what Record reads
            (Record is disabled without one), ``world`` gives object poses.
        ask_path: asks for the waypoint file to import ("" = cancelled); tests replace it.

    Signals:
        message(str): what happened, or why not (for the status bar).
    """

    message = Signal(str)

    def __init__(
        self,
        document: PlanDocument,
        registry: Any = None,
        parent: QWidget | None = None,
        ask_path: PathAsker = _ask_waypoint_file,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.ask_path = ask_path
        self._interfaces: dict[str, Any] = {}
        self._build()
        document.plan_changed.connect(self._refresh)
        document.plan_reset.connect(self._refresh)
        self.set_registry(registry)
        self._refresh()

    def _build(self) -> None:
        self.list = QListWidget()
        self.list.currentRowChanged.connect(lambda _row: self._update_enabled())
        self.name_field = QLineEdit()
        self.name_field.setPlaceholderText("new waypoint's name")
        self.name_field.returnPressed.connect(self.record_from_fields)
        self.frame_combo = QComboBox()
        self.frame_combo.addItems(list(RECORD_FRAMES))
        self.frame_combo.setToolTip(
            "joints: the joint positions; world: the tool pose; object: the tool pose "
            "relative to the object named below, where the cell last saw it"
        )
        self.frame_combo.currentTextChanged.connect(lambda _t: self._update_enabled())
        self.object_field = QLineEdit()
        self.object_field.setPlaceholderText("object, e.g. cup")
        self.record_button = QPushButton("Record")
        self.record_button.setToolTip("Record where the arm is now (move it by hand first)")
        self.record_button.clicked.connect(self.record_from_fields)
        self.import_button = QPushButton("Import…")
        self.import_button.setToolTip("Add the waypoints of a *.waypoints.json file")
        self.import_button.clicked.connect(self._import_asked)
        self.remove_button = QPushButton("Remove")
        self.remove_button.clicked.connect(self.remove_selected)
        record_row = QHBoxLayout()
        for widget in (self.frame_combo, self.object_field, self.record_button):
            record_row.addWidget(widget)
        buttons = QHBoxLayout()
        buttons.addWidget(self.import_button)
        buttons.addWidget(self.remove_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.list, 1)
        layout.addWidget(self.name_field)
        layout.addLayout(record_row)
        layout.addLayout(buttons)

    # ------------------------------------------------------------------ public

    def set_registry(self, registry: Any) -> None:
        """Use another cell: Record reads its arm (and world model)."""
        cell = getattr(registry, "cell", None)
        self._interfaces = dict(cell.interfaces()) if cell is not None else {}
        self._update_enabled()

    def waypoint_names(self) -> list[str]:
        return [w.name for w in self.document.plan.waypoints]

    def record(self, name: str, frame: str = "joints", reference: str = "") -> Waypoint | None:
        """Add (or replace) a waypoint where the arm is now; None with a message when not."""
        name = name.strip()
        if not name:
            self.message.emit("Type a name for the waypoint first.")
            return None
        arm = self._interfaces.get("arm")
        if arm is None:
            self.message.emit("This cell has no arm to record from.")
            return None
        waypoint = self._waypoint_here(arm, name, WaypointFrame(frame), reference.strip())
        if waypoint is not None:
            self._store([waypoint], f"Recorded {_describe(waypoint)}")
        return waypoint

    def record_from_fields(self) -> None:
        """Record with the name, frame and object typed in the panel."""
        done = self.record(
            self.name_field.text(), self.frame_combo.currentText(), self.object_field.text()
        )
        if done is not None:
            self.name_field.clear()

    def import_file(self, path: str | Path) -> int:
        """Add a waypoint file's waypoints (same names are replaced); how many, 0 on error."""
        try:
            library = WaypointLibrary.load(path)
        except WaypointFileError as exc:
            self.message.emit(f"Cannot import the waypoints: {exc}")
            return 0
        waypoints = list(library)
        if waypoints:
            self._store(waypoints, f"Imported {len(waypoints)} waypoints from {Path(path).name}")
        return len(waypoints)

    def remove_selected(self) -> None:
        row = self.list.currentRow()
        current = list(self.document.plan.waypoints)
        if not 0 <= row < len(current):
            return
        gone = current.pop(row)
        self.document.set_plan_field("waypoints", current)
        self.message.emit(f"Removed the waypoint {gone.name!r}")

    # ------------------------------------------------------------------ internals

    def _waypoint_here(
        self, arm: Any, name: str, frame: WaypointFrame, reference: str
    ) -> Waypoint | None:
        if frame is WaypointFrame.JOINTS:
            return Waypoint(name, frame, joints=JointConfig(tuple(arm.joint_positions())))
        tool = arm.tcp_pose()
        if frame is WaypointFrame.WORLD:
            return Waypoint(name, frame, pose=tool)
        world = self._interfaces.get("world")
        seen = world.best(reference) if world is not None and reference else None
        if seen is None:
            self.message.emit(
                f"The cell has not seen {reference or 'that object'}: detect it first."
            )
            return None
        return Waypoint(name, frame, pose=seen.pose.inverse().compose(tool), reference=reference)

    def _store(self, waypoints: Sequence[Waypoint], text: str) -> None:
        """Replace same-named waypoints in place, append the others: one command."""
        by_name = {w.name: w for w in waypoints}
        merged = [by_name.pop(w.name, w) for w in self.document.plan.waypoints]
        merged += list(by_name.values())
        if merged != list(self.document.plan.waypoints):
            self.document.set_plan_field("waypoints", merged)
        self.message.emit(text)

    def _import_asked(self) -> None:
        path = self.ask_path(self)
        if path:
            self.import_file(path)

    def _refresh(self) -> None:
        shown = [_describe(w) for w in self.document.plan.waypoints]
        if shown != [self.list.item(i).text() for i in range(self.list.count())]:
            row = self.list.currentRow()
            self.list.clear()
            self.list.addItems(shown)
            self.list.setCurrentRow(min(row, len(shown) - 1))
        self._update_enabled()

    def _update_enabled(self) -> None:
        self.record_button.setEnabled("arm" in self._interfaces)
        self.object_field.setEnabled(self.frame_combo.currentText() == "object")
        self.remove_button.setEnabled(self.list.currentRow() >= 0)
