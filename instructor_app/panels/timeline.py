"""The Timeline panel: a run record played back, moment by moment.

A slider over the run's time (with play and pause, and the time shown), the failures as red
marks on its track (clicking one goes there), the nodes running at that moment, the cameras'
pictures at that moment (the record's thumbnails, about one a second, in a small picture area
of the panel's own) and the figures of the selected node. The panel says what the views should show as signals; the
window's wiring (:mod:`instructor_app.timeline_wiring`) puts it on the canvas, the
Blackboard panel and the 3D scene.

Dragging stays smooth on a record of 100,000+ transitions: the slider's moves are coalesced
into one update per pass of the event loop, the record answers a moment without going
through itself (:class:`engine.timeline.Timeline`), and only the nodes whose status changed
and the names whose value changed are sent on.
"""

from __future__ import annotations

import math
import time

from PySide6.QtCore import QLine, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QMouseEvent, QPainter, QPaintEvent, QPen, QPixmap
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QStyle,
    QStyleOptionSlider,
    QVBoxLayout,
    QWidget,
)

from engine.blackboard import BlackboardEntry
from engine.status import Status
from engine.timeline import Timeline, changed_statuses
from instructor_app.runtime.run_view import RunningNodesPanel

__all__ = ["TimelinePanel", "TimelineSlider"]

FAILURE_COLOUR = QColor("#b3261e")
_MARK_REACH_PX = 4  # a click this close to a mark goes to it
_PLAY_INTERVAL_MS = 33  # 30 frames a second while playing


class TimelineSlider(QSlider):
    """A horizontal slider (milliseconds) with marks on its track; a click near a mark sets
    the slider to it.

    Signals:
        mark_clicked(int): the mark (its value) the user clicked.
    """

    mark_clicked = Signal(int)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(Qt.Orientation.Horizontal, parent)
        self.setObjectName("TimelineSlider")
        self._marks: list[int] = []
        self._xs: tuple[tuple[int, int, int], list[int]] = ((0, 0, 0), [])  # (key, x per mark)

    def set_marks(self, values: list[int]) -> None:
        self._marks = sorted(values)
        self._xs = ((0, 0, 0), [])
        self.update()

    def marks(self) -> list[int]:
        return list(self._marks)

    def _groove(self) -> tuple[int, int]:
        """(x of the minimum, usable width): where values lie along the track."""
        option = QStyleOptionSlider()
        self.initStyleOption(option)
        style = self.style()
        groove = style.subControlRect(
            QStyle.ComplexControl.CC_Slider, option, QStyle.SubControl.SC_SliderGroove, self
        )
        handle = style.subControlRect(
            QStyle.ComplexControl.CC_Slider, option, QStyle.SubControl.SC_SliderHandle, self
        )
        return groove.x() + handle.width() // 2, groove.width() - handle.width()

    def mark_x(self, value: int) -> int:
        """The x of a value on the track (where its mark is drawn)."""
        left, span = self._groove()
        return left + QStyle.sliderPositionFromValue(self.minimum(), self.maximum(), value, span)

    def _mark_xs(self) -> list[int]:
        """The x of every mark, kept until the slider's width or range changes (a record
        may have thousands of failures: the track is painted at every move).
        """
        key = (self.width(), self.minimum(), self.maximum())
        if self._xs[0] != key:
            left, span = self._groove()
            low, high = self.minimum(), self.maximum()
            position = QStyle.sliderPositionFromValue
            self._xs = (key, [left + position(low, high, v, span) for v in self._marks])
        return self._xs[1]

    def paintEvent(self, event: QPaintEvent) -> None:
        super().paintEvent(event)
        if not self._marks:
            return
        painter = QPainter(self)
        painter.setPen(QPen(FAILURE_COLOUR, 2))
        bottom = self.height() - 3
        painter.drawLines([QLine(x, 2, x, bottom) for x in set(self._mark_xs())])  # one a column
        painter.end()

    def mousePressEvent(self, event: QMouseEvent) -> None:
        x = event.position().x()
        xs = self._mark_xs()
        near = [i for i, mark_x in enumerate(xs) if abs(mark_x - x) <= _MARK_REACH_PX]
        if near and event.button() == Qt.MouseButton.LeftButton:
            mark = self._marks[min(near, key=lambda i: abs(xs[i] - x))]
            self.setValue(mark)
            self.mark_clicked.emit(mark)
            event.accept()
            return
        super().mousePressEvent(event)


class TimelinePanel(QWidget):
    """A run record played back (see the module doc).

    Signals:
        open_requested: Open… was pressed.
        last_run_requested: "Last run" was pressed.
        statuses_changed(dict): node id -> Status, the nodes whose status differs from the
            moment shown before.
        statuses_cleared: another record (or none): the last one's statuses go.
        values_changed(list, bool): the blackboard entries that changed; True when the
            whole blackboard is sent (it held names it did not have yet).
        joints_changed(object): the robot's joints (rad) at the moment, None when unknown.
        node_selected(str): a running node was clicked.
    """

    open_requested = Signal()
    last_run_requested = Signal()
    statuses_changed = Signal(object)  # (a dict through Qt would lose the Status enum)
    statuses_cleared = Signal()
    values_changed = Signal(object, bool)
    joints_changed = Signal(object)
    node_selected = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("TimelinePanel")
        self.timeline: Timeline | None = None
        self._statuses: dict[str, Status] = {}
        self._entries: dict[str, BlackboardEntry] = {}
        self._joints: tuple[float, ...] | None = None
        self._running: list[str] = []
        self._picture_times: dict[str, float | None] = {}  # camera -> when its shown one was taken
        self.picture_labels: dict[str, QLabel] = {}
        self._selected = ""
        self.frames_shown = 0  # moments shown (the bench counts them)
        self.last_changed: dict[str, Status] = {}  # what the last moment shown changed
        self._build()
        self._coalesce = QTimer(self)
        self._coalesce.setSingleShot(True)
        self._coalesce.setInterval(0)
        self._coalesce.timeout.connect(self._show_pending)
        self._player = QTimer(self)
        self._player.setInterval(_PLAY_INTERVAL_MS)
        self._player.timeout.connect(self._advance)
        self._played_from = (0.0, 0.0)  # (the moment, the wall clock) when play was pressed
        self.set_timeline(None)

    def _build(self) -> None:
        style = self.style()
        self.open_button = QPushButton("Open…")
        self.open_button.setToolTip("Open a run record (File > Open Run Record…)")
        self.open_button.clicked.connect(self.open_requested)
        self.last_button = QPushButton("Last run")
        self.last_button.setToolTip("Open the record of the run that just ended")
        self.last_button.clicked.connect(self.last_run_requested)
        self.play_button = QPushButton()
        self.play_button.setObjectName("TimelinePlay")
        self.play_button.setIcon(style.standardIcon(QStyle.StandardPixmap.SP_MediaPlay))
        self.play_button.setCheckable(True)
        self.play_button.setToolTip("Play the run from this moment; again to pause")
        self.play_button.toggled.connect(self.set_playing)
        self.slider = TimelineSlider()
        self.slider.valueChanged.connect(self._moved)
        self.slider.mark_clicked.connect(self._mark_clicked)
        self.time_label = QLabel("")
        self.time_label.setObjectName("TimelineTime")
        self.record_label = QLabel("")
        self.record_label.setObjectName("TimelineRecord")
        self.running = RunningNodesPanel(self._label)
        self.running.node_selected.connect(self.node_selected)
        self.figures_label = QLabel("")
        self.figures_label.setObjectName("TimelineFigures")
        self.figures_label.setWordWrap(True)
        row = QHBoxLayout()
        for widget in (self.open_button, self.last_button, self.play_button):
            row.addWidget(widget)
        row.addWidget(self.slider, 1)
        row.addWidget(self.time_label)
        below = QHBoxLayout()
        column = QVBoxLayout()
        column.addWidget(QLabel("Running at this moment:"))
        column.addWidget(self.running)
        below.addLayout(column, 1)
        self.pictures_row = QHBoxLayout()
        side = QVBoxLayout()
        side.addWidget(self.record_label)
        side.addWidget(self.figures_label)
        side.addLayout(self.pictures_row)
        side.addStretch(1)
        below.addLayout(side, 1)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(row)
        layout.addLayout(below, 1)

    # ------------------------------------------------------------------ the record

    def set_timeline(self, timeline: Timeline | None) -> None:
        """Show a record from its start (None: none)."""
        self.set_playing(False)
        self.timeline = timeline
        self._statuses, self._entries, self._joints, self._running = {}, {}, None, []
        self.statuses_cleared.emit()
        self._set_cameras(timeline.cameras if timeline is not None else [])
        has = timeline is not None
        for widget in (self.slider, self.play_button):
            widget.setEnabled(has)
        if timeline is None:
            self.record_label.setText("No run record open: Open… or Last run")
            self.slider.set_marks([])
            self.running.set_nodes([])
            self.time_label.setText("")
            self.figures_label.setText("")
            return
        count = len(timeline.failures)
        self.record_label.setText(
            f"{timeline.name}: {timeline.transitions} transitions, "
            f"{count} failure{'s' * (count != 1)} (red marks: click one to go there)"
        )
        self.slider.blockSignals(True)
        self.slider.setRange(0, _ms(timeline.duration))
        self.slider.setValue(0)
        self.slider.blockSignals(False)
        self.slider.set_marks([_ms(mark.time) for mark in timeline.failures])
        self.slider.setToolTip("\n".join(self._mark_tips()[:20]))
        # As wide as its widest text: a label that changes width at every move would lay the
        # row out again, and the slider's marks with it.
        widest = f"{timeline.duration:.2f} s / {timeline.duration:.2f} s".replace("1", "0")
        self.time_label.setFixedWidth(self.time_label.fontMetrics().horizontalAdvance(widest) + 8)
        self.show_time(0.0)
        self.show_figures(self._selected)

    def _mark_tips(self) -> list[str]:
        assert self.timeline is not None
        return [
            f"{m.time:.2f} s: {self._label(m.node_id)} failed"
            + (f" ({m.error}): {m.message}" if m.message else "")
            for m in self.timeline.failures
        ]

    def _label(self, node_id: str) -> str:
        return self.timeline.label(node_id) if self.timeline is not None else node_id

    # ------------------------------------------------------------------ moments

    @property
    def time(self) -> float:
        """The moment shown (seconds since the run started)."""
        return self.slider.value() / 1000.0

    def show_time(self, t: float) -> None:
        """Show the moment ``t`` (seconds since the start) at once."""
        self.slider.blockSignals(True)
        self.slider.setValue(_ms(t))
        self.slider.blockSignals(False)
        self._show(self.slider.value())

    def _moved(self, _value: int) -> None:
        if not self._coalesce.isActive():  # several moves before the next pass: one update
            self._coalesce.start()

    def _show_pending(self) -> None:
        self._show(self.slider.value())

    def _show(self, ms: int, index: int | None = None) -> None:
        """Show the moment ``ms``; ``index``: after that many transitions (default: all of
        those up to ``ms``).
        """
        timeline = self.timeline
        if timeline is None:
            return
        t = ms / 1000.0
        index = timeline.index_at(t) if index is None else index
        self.time_label.setText(f"{t:.2f} s / {timeline.duration:.2f} s")
        statuses = timeline.statuses_after(index)
        changed = changed_statuses(self._statuses, statuses)
        self._statuses = statuses
        self.last_changed = changed
        if changed:
            self.statuses_changed.emit(changed)
        self._show_values(timeline.values_at(t))
        joints = timeline.joints_at(t)
        if joints != self._joints:
            self._joints = joints
            self.joints_changed.emit(joints)
        self._show_pictures(t)
        running = timeline.running_after(index)
        if running != self._running:
            self._running = running
            self.running.set_nodes(running)
        self.frames_shown += 1

    def _show_values(self, entries: list[BlackboardEntry]) -> None:
        now = {entry.key: entry for entry in entries}
        if any(key not in now for key in self._entries):  # back before a first write
            self._entries = now
            self.values_changed.emit(entries, True)
            return
        changed = [e for e in entries if self._entries.get(e.key) is not e]
        self._entries = now
        if changed:
            self.values_changed.emit(changed, False)

    def _set_cameras(self, cameras: list[str]) -> None:
        """One picture per camera of the record, captioned with its name (none: no area)."""
        for label in self.picture_labels.values():
            self.pictures_row.removeWidget(label)
            label.deleteLater()
        self.picture_labels, self._picture_times = {}, {}
        for camera in cameras:
            label = QLabel(f"{camera}: no picture yet")
            label.setObjectName(f"TimelinePicture-{camera}")
            label.setToolTip(f"The {camera} camera at this moment (a picture a second)")
            label.setMinimumSize(160, 120)
            label.setAlignment(Qt.AlignmentFlag.AlignCenter)
            self.pictures_row.addWidget(label)
            self.picture_labels[camera] = label

    def _show_pictures(self, t: float) -> None:
        """Each camera's picture at ``t``, decoded only when it is another one."""
        timeline = self.timeline
        assert timeline is not None
        taken = {camera: timeline.picture_time(camera, t) for camera in self.picture_labels}
        if taken == self._picture_times:
            return
        pictures = timeline.pictures_at(t)
        for camera, label in self.picture_labels.items():
            if taken[camera] == self._picture_times.get(camera, -1.0):
                continue
            pixmap = QPixmap()
            if camera in pictures and pixmap.loadFromData(pictures[camera]):
                label.setPixmap(pixmap)
            else:
                label.clear()
                label.setText(f"{camera}: no picture yet")
        self._picture_times = taken

    def picture(self, camera: str) -> QPixmap | None:
        """The picture shown of ``camera`` (None: none)."""
        label = self.picture_labels.get(camera)
        pixmap = label.pixmap() if label is not None else None
        return pixmap if pixmap is not None and not pixmap.isNull() else None

    def _mark_clicked(self, value: int) -> None:
        assert self.timeline is not None
        marks = [_ms(mark.time) for mark in self.timeline.failures]
        self._coalesce.stop()
        self.go_to_failure(marks.index(value))

    def statuses(self) -> dict[str, Status]:
        """Every node's status at the moment shown."""
        return dict(self._statuses)

    def go_to_failure(self, number: int) -> None:
        """Show the moment of the record's ``number``-th failure, just after the node failed
        (a retry may reset it in the same millisecond).
        """
        assert self.timeline is not None
        mark = self.timeline.failures[number]
        self.slider.blockSignals(True)
        self.slider.setValue(_ms(mark.time))
        self.slider.blockSignals(False)
        self._show(self.slider.value(), mark.index + 1)

    # ------------------------------------------------------------------ play

    def set_playing(self, playing: bool) -> None:
        """Play the run on from the moment shown, in real time (False: pause)."""
        if playing and self.timeline is not None:
            if self.slider.value() >= self.slider.maximum():
                self.show_time(0.0)
            self._played_from = (self.time, time.monotonic())
            self._player.start()
        else:
            self._player.stop()
        icon = (
            QStyle.StandardPixmap.SP_MediaPause if playing else QStyle.StandardPixmap.SP_MediaPlay
        )
        self.play_button.blockSignals(True)
        self.play_button.setChecked(self._player.isActive())
        self.play_button.blockSignals(False)
        self.play_button.setIcon(self.style().standardIcon(icon))

    @property
    def playing(self) -> bool:
        return self._player.isActive()

    def _advance(self) -> None:
        start, wall = self._played_from
        t = start + time.monotonic() - wall
        self.show_time(t)
        if self.slider.value() >= self.slider.maximum():
            self.set_playing(False)

    # ------------------------------------------------------------------ figures

    def show_figures(self, node_id: str | None) -> None:
        """Show what the node did over the run (its figures) under the record's name."""
        self._selected = node_id or ""
        timeline = self.timeline
        if timeline is None or not node_id:
            self.figures_label.setText("Select a node to see what it did in this run.")
            return
        f = timeline.figures(node_id)
        self.figures_label.setText(
            f"<b>{self._label(node_id)}</b>: ticked {f.ticks} times, started {f.starts}, "
            f"{f.successes} successes, {f.failures} failures, RUNNING for {f.running_s:.2f} s"
        )


def _ms(seconds: float) -> int:
    """The slider's value of a moment: milliseconds, rounded up (a failure's mark shows it)."""
    return max(0, math.ceil(seconds * 1000 - 1e-6))
