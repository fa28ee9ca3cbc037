"""The plan's waypoints (``PlanSpec.waypoints``): the list the inspector's waypoint fields offer.

A worker teaches a waypoint by moving the arm (freedrive, jogging) and pressing Record: the
panel reads the arm's measured joints or tool pose from the cell, or, for a "smart waypoint",
the tool pose in the frame of the object or marker the cell recognised nearest to the tool
(or the one named). The selected waypoint can be renamed, its numbers edited, taught again
where the arm is now, previewed, and driven to with the held Move here button (at reduced
speed; let go and the arm stops, as on PolyScope). Waypoints taught earlier come in from a
waypoint file (``*.waypoints.json``, :class:`capabilities.waypoints.WaypointLibrary`).
Every change is one document command; a changed waypoint also changes the nodes using it.
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
from engine.types import Waypoint, WaypointFrame
from instructor_app.document import DocumentError, PlanDocument
from instructor_app.panels.waypoint_details import WaypointDetails
from instructor_app.runtime.waypoint_teach import TeachError, teach_like, teach_waypoint

__all__ = ["WaypointsPanel", "WAYPOINT_FILTER", "PathAsker"]

WAYPOINT_FILTER = "CoSTAR waypoints (*.waypoints.json);;JSON files (*.json);;All files (*)"
RECORD_FRAMES = ("joints", "world", "object", "marker")

PathAsker = Callable[[QWidget], str]


def _ask_waypoint_file(parent: QWidget) -> str:
    return QFileDialog.getOpenFileName(parent, "Import waypoints", "", WAYPOINT_FILTER)[0]


def _describe(waypoint: Waypoint) -> str:
    where = f" of {waypoint.reference}" if waypoint.reference else ""
    return f"{waypoint.name} ({waypoint.frame.value}{where})"


def _button(text: str, tip: str, name: str = "") -> QPushButton:
    button = QPushButton(text)
    button.setToolTip(tip)
    if name:
        button.setObjectName(name)
    return button


class WaypointsPanel(QWidget):
    """Lists, records, edits, imports, removes and drives to the plan's waypoints.

    Args:
        document: the plan being edited.
        registry: the cell's registry; its cell's ``arm`` interface is what Record reads
            (Record is disabled without one), ``world`` gives recognised objects and markers.
        ask_path: asks for the waypoint file to import ("" = cancelled); tests replace it.
        teacher: moves the robot (Move here); None: no Move here.

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
        teacher: Any = None,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.ask_path = ask_path
        self.teacher = teacher
        self.scene: Any = None  # the 3D scene that previews (a ghost arm), when there is one
        self._interfaces: dict[str, Any] = {}
        self._build()
        document.plan_changed.connect(self._refresh)
        document.plan_reset.connect(self._refresh)
        if teacher is not None:
            teacher.availability_changed.connect(self._update_enabled)
            teacher.preview_ready.connect(self._show_ghost)
        self.set_registry(registry)
        self._refresh()

    def _build(self) -> None:
        self.list = QListWidget()
        self.list.currentRowChanged.connect(lambda _row: self._selection_changed())
        self.list.itemDoubleClicked.connect(self._focus_name)
        self.name_field = QLineEdit()
        self.name_field.setPlaceholderText("new waypoint's name")
        self.name_field.returnPressed.connect(self.record_from_fields)
        self.frame_combo = QComboBox()
        self.frame_combo.addItems(list(RECORD_FRAMES))
        self.frame_combo.setToolTip(
            "joints: the joint positions; world: the tool pose; object / marker: the tool "
            "pose relative to the recognised object (marker) nearest the tool, or the one named"
        )
        self.frame_combo.currentTextChanged.connect(lambda _t: self._update_enabled())
        self.object_field = QLineEdit()
        self.object_field.setPlaceholderText("nearest recognised")
        self.object_field.setToolTip("An object class (cup) or marker id; empty: the nearest")
        self.record_button = _button("Record", "Record where the arm is now (move it first)")
        self.record_button.clicked.connect(self.record_from_fields)
        self.details = WaypointDetails()
        self.details.edited.connect(self._details_edited)
        self.teach_button = _button("Teach", "Teach the selected waypoint again, here")
        self.teach_button.clicked.connect(self.teach_selected)
        self.move_button = _button(
            "Move here",
            "Hold down to drive the arm to the selected waypoint at reduced speed; "
            "let go and it stops",
            "WaypointMoveHere",
        )
        self.move_button.pressed.connect(self._move_pressed)
        self.move_button.released.connect(self._move_released)
        self.preview_button = _button("Preview", "Show the arm at the waypoint in the 3D scene")
        self.preview_button.setCheckable(True)
        self.preview_button.toggled.connect(lambda _on: self._preview())
        self.import_button = _button("Import…", "Add the waypoints of a *.waypoints.json file")
        self.import_button.clicked.connect(self._import_asked)
        self.remove_button = _button("Remove", "Remove the selected waypoint")
        self.remove_button.clicked.connect(self.remove_selected)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        # What a worker uses most comes first: record, the list, drive there; then details.
        layout.addLayout(self._row(self.name_field, self.record_button))
        layout.addLayout(self._row(self.frame_combo, self.object_field))
        layout.addWidget(self.list, 1)
        layout.addLayout(self._row(self.move_button, self.teach_button, self.preview_button))
        layout.addWidget(self.details)
        layout.addLayout(self._row(self.import_button, self.remove_button))

    def _focus_name(self, _item: object) -> None:
        self.details.name_edit.setFocus()
        self.details.name_edit.selectAll()

    @staticmethod
    def _row(*widgets: QWidget) -> QHBoxLayout:
        row = QHBoxLayout()
        for widget in widgets:
            row.addWidget(widget)
        return row

    # ------------------------------------------------------------------ public

    def set_registry(self, registry: Any) -> None:
        """Use another cell: Record reads its arm (and world model)."""
        cell = getattr(registry, "cell", None)
        self._interfaces = dict(cell.interfaces()) if cell is not None else {}
        self._update_enabled()

    def set_scene(self, scene: Any) -> None:
        """The 3D scene whose ghost arm (``show_ghost(joints | None)``) previews the selected
        waypoint; None or a scene without OpenGL: no preview.
        """
        self.scene = scene if scene is not None and getattr(scene, "available", True) else None
        self._update_enabled()

    def waypoint_names(self) -> list[str]:
        return [w.name for w in self.document.plan.waypoints]

    def selected(self) -> Waypoint | None:
        row = self.list.currentRow()
        waypoints = self.document.plan.waypoints
        return waypoints[row] if 0 <= row < len(waypoints) else None

    def select(self, name: str) -> None:
        if name in self.waypoint_names():
            self.list.setCurrentRow(self.waypoint_names().index(name))

    def record(self, name: str, frame: str = "joints", reference: str = "") -> Waypoint | None:
        """Add (or replace) a waypoint where the arm is now; None with a message when not."""
        try:
            waypoint = teach_waypoint(self._interfaces, name, WaypointFrame(frame), reference)
        except TeachError as exc:
            self.message.emit(f"{str(exc)[:1].upper()}{str(exc)[1:]}.")
            return None
        self._store([waypoint], f"Recorded {_describe(waypoint)}")
        self.select(waypoint.name)
        return waypoint

    def record_from_fields(self) -> None:
        """Record with the name, frame and object typed in the panel."""
        done = self.record(
            self.name_field.text(), self.frame_combo.currentText(), self.object_field.text()
        )
        if done is not None:
            self.name_field.clear()

    def teach_selected(self) -> Waypoint | None:
        """Teach the selected waypoint again where the arm is now (same frame, reference)."""
        current = self.selected()
        if current is None:
            return None
        try:
            taught = teach_like(self._interfaces, current)
        except TeachError as exc:
            self.message.emit(f"Cannot teach {current.name!r}: {exc}.")
            return None
        self._replace(current.name, taught, f"Taught {_describe(taught)} again")
        return taught

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
        current = self.document.plan.waypoints
        if not 0 <= row < len(current):
            return
        gone = current[row].name
        self.document.remove_waypoint(gone)
        self.message.emit(f"Removed the waypoint {gone!r}")

    # ------------------------------------------------------------------ internals

    def _store(self, waypoints: Sequence[Waypoint], text: str) -> None:
        """Replace same-named waypoints in place, append the others: one command."""
        self.document.store_waypoints(list(waypoints))
        self.message.emit(text)

    def _replace(self, old_name: str, new: Waypoint, text: str) -> bool:
        try:
            self.document.replace_waypoint(old_name, new, text)
        except DocumentError as exc:
            self.message.emit(f"Cannot change {old_name!r}: {exc}")
            self.details.show_waypoint(self.selected())
            return False
        self.select(new.name)
        self.message.emit(text)
        return True

    def _details_edited(self, waypoint: object) -> None:
        current = self.selected()
        if current is not None and isinstance(waypoint, Waypoint):
            self._replace(current.name, waypoint, f"Changed {_describe(waypoint)}")

    def _move_pressed(self) -> None:
        waypoint = self.selected()
        if waypoint is not None and self.teacher is not None:
            self.teacher.hold_move_to(waypoint, "", f"move to {waypoint.name}")

    def _move_released(self) -> None:
        if self.teacher is not None:
            self.teacher.release()

    def _preview(self) -> None:
        """The ghost arm at the selected waypoint (worked out on the teacher's worker)."""
        if self.scene is None or self.teacher is None:
            return
        waypoint = self.selected() if self.preview_button.isChecked() else None
        if waypoint is None:
            self.scene.show_ghost(None)
        else:
            self.teacher.preview(waypoint)

    def _show_ghost(self, joints: object) -> None:
        if self.scene is not None and self.preview_button.isChecked():
            self.scene.show_ghost(joints)

    def _import_asked(self) -> None:
        path = self.ask_path(self)
        if path:
            self.import_file(path)

    def _selection_changed(self) -> None:
        self.details.show_waypoint(self.selected())
        self._preview()
        self._update_enabled()

    def _refresh(self) -> None:
        shown = [_describe(w) for w in self.document.plan.waypoints]
        if shown != [self.list.item(i).text() for i in range(self.list.count())]:
            row = self.list.currentRow()
            self.list.clear()
            self.list.addItems(shown)
            self.list.setCurrentRow(min(row, len(shown) - 1))
        self.details.show_waypoint(self.selected())
        self._update_enabled()

    def _update_enabled(self) -> None:
        chosen = self.selected() is not None
        self.record_button.setEnabled("arm" in self._interfaces)
        self.object_field.setEnabled(self.frame_combo.currentText() in ("object", "marker"))
        self.remove_button.setEnabled(chosen)
        self.teach_button.setEnabled(chosen and "arm" in self._interfaces)
        reason = self.teacher.unavailable_reason("arm") if self.teacher else "no robot to move"
        self.move_button.setEnabled(chosen and not reason)
        self.move_button.setToolTip(
            reason.capitalize() if reason else "Hold down to drive the arm to the waypoint"
        )
        self.preview_button.setEnabled(chosen and self.scene is not None)
