"""The Timeline panel in the main window: opening run records and showing their moments.

:class:`TimelineController` opens a record (File > Open Run Record…, the panel's Open… and
"Last run"), puts the plan it ran in the canvas (the plan shown when it is the same plan,
else the record's, after asking to save unsaved changes), and shows the panel's moments:
statuses on the canvas, values in the Blackboard panel, the robot's joints as the 3D scene's
ghost arm. Nothing here draws.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, Signal
from PySide6.QtWidgets import QWidget

from engine.files import dump_plan
from engine.run_records import RunRecordError, find_record, runs_folder
from engine.spec import PlanSpec
from engine.timeline import Timeline
from engine.trace import TraceError
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.panels.timeline import TimelinePanel

__all__ = ["TimelineController"]


def _ids(plan: PlanSpec) -> set[str]:
    return {node.id for _, node in plan.walk()}


class TimelineController(QObject):
    """Opens run records into the Timeline panel and shows their moments on the views.

    Args:
        panel: the Timeline panel.
        document: the plan in the canvas.
        views: the window's views (canvas, blackboard).
        scene3d: the 3D scene (its ghost arm shows the robot's joints).
        window: asks the questions (its ``dialogs``, ``maybe_save``, ``show_canvas``,
            ``select_node``).
        last_record: the record of the last run the window started (None: none yet).
        folder: the runs folder now (the setting may change it).

    Signals:
        message(str): a line for the status bar.
    """

    message = Signal(str)

    def __init__(
        self,
        panel: TimelinePanel,
        document: PlanDocument,
        views: Any,
        scene3d: Any,
        window: Any,
        last_record: Callable[[], Path | None],
        parent: QObject | None = None,
        folder: Callable[[], Path] = runs_folder,
    ) -> None:
        super().__init__(parent)
        self.panel, self.document, self._window = panel, document, window
        self._canvas, self._blackboard, self._scene3d = views.canvas, views.blackboard, scene3d
        self._last_record = last_record
        self._folder = folder
        panel.open_requested.connect(lambda: self.open_record())
        panel.last_run_requested.connect(self.open_last_run)
        panel.statuses_changed.connect(self._canvas.set_statuses)
        panel.statuses_cleared.connect(self._canvas.clear_statuses)
        panel.values_changed.connect(self._show_values)
        panel.joints_changed.connect(self._show_joints)
        panel.node_selected.connect(window.select_node)
        self._canvas.selection_changed.connect(
            lambda ids: panel.show_figures(ids[0] if len(ids) == 1 else None)
        )

    def open_record(self, path: str | Path | None = None) -> bool:
        """Open a run record (asks for the file when ``path`` is None); False when not."""
        if path is None:
            parent: QWidget = self._window
            path = self._window.dialogs.record_open_path(parent, str(self._folder()))
            if not path:
                return False
        try:
            timeline = Timeline.load(path)
        except TraceError as exc:
            self._window.dialogs.error(self._window, "Open run record", str(exc))
            return False
        self._use_plan(timeline)
        self.panel.set_timeline(timeline)
        self._window.raise_dock("timeline")
        self.message.emit(f"Run record {timeline.name}: drag the slider to see each moment")
        return True

    def open_last_run(self) -> bool:
        """Open the record of the run that just ended (else the newest in the runs folder)."""
        path = self._last_record()
        if path is None or not path.exists():
            try:
                path = find_record(self._folder(), "last")
            except RunRecordError as exc:
                self.message.emit(f"No run record to open: {exc}")
                return False
        return self.open_record(path)

    def _use_plan(self, timeline: Timeline) -> None:
        """The canvas shows the plan the record ran: the document's when it is the same."""
        plan = timeline.plan()
        if plan is None or _ids(plan) == _ids(self.document.plan):
            return
        if not self._window.maybe_save():
            self.message.emit("The canvas keeps its plan: only its nodes in the record are shown")
            return
        try:
            self.document.load_text(dump_plan(plan), None, source=timeline.name)
        except DocumentError as exc:
            self.message.emit(f"The record's plan cannot be shown: {exc}")
            return
        self._window.show_canvas()

    def _show_values(self, entries: Any, whole: bool) -> None:
        if whole:
            self._blackboard.clear()
        self._blackboard.set_entries(entries)

    def _show_joints(self, joints: Any) -> None:
        self._scene3d.show_ghost(list(joints) if joints is not None else None)
