"""The camera panel: live colour and depth of the cell's cameras, with what the cell believes.

Each camera (``rgbd:<name>`` of the cell: shoulder and wrist in simulation) gets a row: the
colour picture and the depth picture, both with the overlays of
:class:`~instructor_app.runtime.overlays.OverlayPainter` (detected objects with class and
confidence, markers, the plan's regions). Frames are captured and drawn by a
:class:`~instructor_app.runtime.camera_feed.CameraFeed` thread; a GUI timer only shows the
newest picture of each camera when it changed, and stops once no new picture came for
``IDLE_POLLS`` turns (an idle cell gives none: nothing in view moved); the feed wakes it
again with the next picture. A hidden or paused panel captures nothing.
A camera that gives no picture (the simulated cell's live-view renderer stopped, a camera
failed) says so on its pictures' captions, with the reason in the toolbar; the rest of the
app goes on.

Regions by pointing: with "Draw region" on, press on a depth picture where the region's
centre is and drag out its radius; on release ``region_drawn(Region)`` fires (the window saves
it in the plan, :func:`instructor_app.document.regions.save_region`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QFileDialog,
    QGraphicsEllipseItem,
    QLabel,
    QPushButton,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from engine.plan_writer import write_atomic
from engine.types import Region
from instructor_app.runtime.camera_feed import CameraFeed, FeedFrame
from instructor_app.runtime.overlays import OverlayPainter, unproject

__all__ = ["CameraPanel", "camera_interfaces"]

PathAsker = Callable[[QWidget], str]
POLL_MS = 30  # the GUI looks for new frames ~33 times a second while they come
IDLE_POLLS = 10  # turns without a new frame after which the timer stops until the next one
# Each camera is captured a little above the 15 pictures a second the panel should show: a
# picture is shown at most once, and one that a late GUI turn finds already replaced by the
# next is never shown, so a feed at exactly 15 shows 14-15 (bench/cell_views.py).
LIVE_FPS = 16.0


def camera_interfaces(cell: Any) -> dict[str, Any]:
    """Name -> camera interface of the cell's ``rgbd:<name>`` interfaces."""
    if cell is None:
        return {}
    return {k.split(":", 1)[1]: v for k, v in cell.interfaces().items() if k.startswith("rgbd:")}


def _ask_png(parent: QWidget) -> str:
    return QFileDialog.getSaveFileName(
        parent, "Save camera snapshot", "cameras.png", "PNG (*.png)"
    )[0]


class _Picture(pg.ImageItem):
    """A camera picture that lets the panel draw a region on it with the mouse."""

    def __init__(self, panel: CameraPanel, camera: str, depth: bool) -> None:
        super().__init__(axisOrder="row-major")
        self.panel, self.camera, self.is_depth = panel, camera, depth

    def mousePressEvent(self, ev: Any) -> None:
        if self.panel.drawing and ev.button() == Qt.MouseButton.LeftButton:
            pos = ev.pos()
            if self.panel.begin_region(self.camera, pos.x(), pos.y()):
                ev.accept()
                return
        super().mousePressEvent(ev)

    def mouseMoveEvent(self, ev: Any) -> None:
        self.panel.drag_region(ev.pos().x(), ev.pos().y())

    def mouseReleaseEvent(self, ev: Any) -> None:
        self.panel.finish_region()


class CameraPanel(QWidget):
    """Colour and depth of every camera of the cell, live, with overlays.

    Args:
        fps: the target rate of each camera.
        ask_path: asks where to save a snapshot ("" = cancelled); tests replace it.

    Signals:
        region_drawn(object): an ``engine.types.Region`` drawn on a depth picture.
        message(str): what happened, or why not (for the status bar).
    """

    region_drawn = Signal(object)
    message = Signal(str)
    _frame_left = Signal()  # the feed left a frame or a failure (emitted on its thread)

    def __init__(
        self, fps: float = LIVE_FPS, ask_path: PathAsker = _ask_png, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.setObjectName("CameraPanel")
        self.fps = fps
        self._ask_path = ask_path
        self.feed: CameraFeed | None = None
        self.painter = OverlayPainter()
        self.shown: dict[str, FeedFrame] = {}
        self.frames_shown = 0  # pictures put on screen (a camera's frame counts once)
        self.drawing = False
        self._regions: tuple[tuple[str, Region], ...] = ()
        # A region being drawn: (camera, centre in the world, its depth, centre pixel u, v).
        self._draft: tuple[str, tuple[float, float, float], float, float, float] | None = None
        self._draft_radius_px = 0.0
        self._pictures: dict[str, tuple[_Picture, _Picture]] = {}
        self._labels: dict[str, list[pg.TextItem]] = {}  # the captions on each camera's pictures
        self._stopped: frozenset[str] = frozenset()  # cameras captioned as giving no picture
        self._build()
        self._timer = QTimer(self)
        self._timer.setInterval(POLL_MS)
        self._timer.timeout.connect(self._poll)
        self._idle_polls = 0
        self.timer_stops = 0  # times the timer stopped because no new picture came
        self._frame_left.connect(self._wake)  # queued: the feed's thread emits it

    def _build(self) -> None:
        self.pause_button = QPushButton("Pause")
        self.pause_button.setCheckable(True)
        self.pause_button.toggled.connect(lambda _: self._update_active())
        self.snapshot_button = QPushButton("Snapshot…")
        self.snapshot_button.clicked.connect(lambda: self.snapshot())
        self.draw_button = QPushButton("Draw region")
        self.draw_button.setCheckable(True)
        self.draw_button.setToolTip(
            "Press on a depth picture at the region's centre, drag its radius"
        )
        self.draw_button.toggled.connect(self._set_drawing)
        self.overlay_box = QCheckBox("Overlays")
        self.overlay_box.setChecked(True)
        self.overlay_box.toggled.connect(self._set_overlays)
        self.rate_label = QLabel("")
        bar = QToolBar()  # a narrow dock folds its buttons into the toolbar's menu
        for widget in (self.pause_button, self.snapshot_button, self.draw_button, self.overlay_box):
            bar.addWidget(widget)
        bar.addWidget(self.rate_label)
        self.view = pg.GraphicsLayoutWidget()
        self.view.setBackground("#202020")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(bar)
        layout.addWidget(self.view, 1)
        self._draft_item = QGraphicsEllipseItem()
        self._draft_item.setPen(pg.mkPen((255, 60, 200), width=2))

    # ------------------------------------------------------------------ cell

    def set_cell(self, cell: Any) -> None:
        """Show the cameras of another cell (None: no cameras)."""
        self.stop()
        self.view.clear()
        self._pictures.clear()
        self._labels.clear()
        self._stopped = frozenset()
        self.shown.clear()
        interfaces = cell.interfaces() if cell is not None else {}
        layout = interfaces.get("scene_layout") or {}
        self.painter = OverlayPainter(
            interfaces.get("world"), interfaces.get("objects"), layout.get("marker_sizes", {})
        )
        self.painter.set_regions(self._regions)
        cameras = camera_interfaces(cell)
        for row, name in enumerate(sorted(cameras)):
            pictures = []
            for col, depth in enumerate((False, True)):
                box = self.view.addViewBox(
                    row=row, col=col, lockAspect=True, invertY=True, enableMenu=False
                )
                picture = _Picture(self, name, depth)
                box.addItem(picture)
                label = pg.TextItem(
                    f"{name} {'depth' if depth else 'colour'}",
                    color=(240, 240, 240),
                    anchor=(0, 0),
                    fill=(0, 0, 0, 140),
                )
                box.addItem(label)
                self._labels.setdefault(name, []).append(label)
                pictures.append(picture)
            self._pictures[name] = (pictures[0], pictures[1])
        self.feed = CameraFeed(cameras, self.painter, self.fps, on_frame=self._frame_left.emit)
        feed = self.feed  # a panel deleted without stop() still ends its thread
        self.destroyed.connect(lambda *_: feed.stop(0.5))
        # cleared too: a cell with cameras after one without (the window starts on none)
        self.rate_label.setText("" if cameras else "this cell has no cameras")
        self._update_active()

    def set_regions(self, regions: Iterable[tuple[str, Region]]) -> None:
        """The plan's regions to draw (name, sphere)."""
        self._regions = tuple(regions)
        self.painter.set_regions(self._regions)

    def stop(self) -> None:
        """Stop capturing (before the cell closes)."""
        self._timer.stop()
        if self.feed is not None:
            self.feed.stop()
            self.feed = None

    # ------------------------------------------------------------------ showing

    @property
    def paused(self) -> bool:
        return self.pause_button.isChecked()

    def showEvent(self, event: Any) -> None:
        super().showEvent(event)
        self._update_active()

    def hideEvent(self, event: Any) -> None:
        super().hideEvent(event)
        self._update_active()

    def _update_active(self) -> None:
        """Capture while the panel shows and is not paused; otherwise the cell renders nothing."""
        feed = self.feed
        if feed is None:
            return
        live = self.isVisible() and not self.paused
        feed.set_active(set(feed.cameras) if live else set())
        if live:
            feed.start()
            self._idle_polls = 0
            self._timer.start()
            self._rate_start, self._rate_frames = time.perf_counter(), self.frames_shown
        else:
            self._timer.stop()

    @property
    def polling(self) -> bool:
        """True while the GUI's timer looks for new pictures (False when idle or not live)."""
        return self._timer.isActive()

    def _wake(self) -> None:
        """A new picture (or a failure) came: look for pictures again if the timer slept."""
        feed = self.feed
        if feed is not None and feed.active and not self._timer.isActive():
            self._idle_polls = 0
            self._timer.start()
            self._poll()

    def _poll(self) -> None:
        if self.feed is None:
            return
        before = self.frames_shown
        for name, (colour, depth) in self._pictures.items():
            latest = self.feed.latest(name)
            if latest is None or (name in self.shown and self.shown[name].seq == latest.seq):
                continue
            colour.setImage(latest.rgb, autoLevels=False, levels=(0, 255))
            depth.setImage(latest.depth, autoLevels=False, levels=(0, 255))
            self.shown[name] = latest
            self.frames_shown += 1
        failures = dict(self.feed.failures)
        if frozenset(failures) != self._stopped:
            self._stopped = frozenset(failures)
            self._caption(self._stopped)
        self._idle_polls = 0 if self.frames_shown != before else self._idle_polls + 1
        idle = self._idle_polls >= IDLE_POLLS
        if idle:  # nothing new: sleep until the feed leaves a frame or a failure
            self._timer.stop()
            self.timer_stops += 1
            self._rate_start, self._rate_frames = time.perf_counter(), self.frames_shown
        if failures:  # e.g. the simulated cell's live-view renderer stopped: say so
            text = "; ".join(f"{name}: {why}" for name, why in sorted(failures.items()))
            self.rate_label.setText(f"No live picture ({text})")
            self.rate_label.setToolTip(text)
            return
        if idle:
            self.rate_label.setText("still")
            return
        elapsed = time.perf_counter() - self._rate_start
        if elapsed > 1.0:
            per_camera = (
                (self.frames_shown - self._rate_frames) / elapsed / max(len(self._pictures), 1)
            )
            self.rate_label.setText(f"{per_camera:.0f} fps")
            self._rate_start, self._rate_frames = time.perf_counter(), self.frames_shown

    def _caption(self, failures: frozenset[str]) -> None:
        """Caption each picture with its camera, or say on it that no live picture comes."""
        for name, labels in self._labels.items():
            for label, kind in zip(labels, ("colour", "depth"), strict=True):
                stopped = name in failures
                label.setText(f"{name} {kind}" + (": NO LIVE PICTURE" if stopped else ""))
                label.fill = pg.mkBrush((170, 0, 0, 200) if stopped else (0, 0, 0, 140))

    def _set_overlays(self, on: bool) -> None:
        self.painter.show_objects = self.painter.show_markers = self.painter.show_regions = on

    def snapshot(self, path: str | Path | None = None) -> Path | None:
        """Save the pictures shown now (colour and depth of each camera, overlays drawn) as
        one PNG; asks for the file when ``path`` is None. Returns the file, or None.
        """
        if not self.shown:
            self.message.emit("No camera picture to save yet")
            return None
        chosen = str(path) if path is not None else self._ask_path(self)
        if not chosen:
            return None
        rows = [np.hstack((f.rgb, f.depth)) for _, f in sorted(self.shown.items())]
        width = max(r.shape[1] for r in rows)
        rows = [np.pad(r, ((0, 0), (0, width - r.shape[1]), (0, 0))) for r in rows]
        ok, data = cv2.imencode(".png", np.vstack(rows)[:, :, ::-1])
        if not ok:
            self.message.emit("The snapshot could not be encoded as PNG")
            return None
        target = Path(chosen)
        write_atomic(target, data.tobytes())
        self.message.emit(f"Saved the camera pictures to {target}")
        return target

    # ------------------------------------------------------------------ regions by pointing

    def _set_drawing(self, on: bool) -> None:
        self.drawing = on
        for _, depth in self._pictures.values():
            depth.setCursor(Qt.CursorShape.CrossCursor if on else Qt.CursorShape.ArrowCursor)

    def begin_region(self, camera: str, u: float, v: float) -> bool:
        """Start a region at pixel (u, v) of a camera's picture: its centre is the point seen
        there (the depth at that pixel, or the nearest valid one within a few pixels).
        """
        shown = self.shown.get(camera)
        if shown is None:
            return False
        z = _depth_near(shown.frame.depth, round(u), round(v))
        if z is None:
            self.message.emit("No depth there: press on something the camera sees")
            return False
        centre = unproject(shown.frame, u, v, z)
        self._draft = (camera, centre, z, u, v)
        self._draft_item.setRect(u, v, 0, 0)
        box = self._pictures[camera][1].getViewBox()
        if box is not None and self._draft_item.scene() is None:
            box.addItem(self._draft_item)
        return True

    def drag_region(self, u: float, v: float) -> None:
        if self._draft is None:
            return
        _, _, _, u0, v0 = self._draft
        r = float(np.hypot(u - u0, v - v0))
        self._draft_item.setRect(u0 - r, v0 - r, 2 * r, 2 * r)
        self._draft_radius_px = r

    def finish_region(self) -> Region | None:
        """End the drag: the radius is the dragged distance at the centre's depth."""
        if self._draft is None:
            return None
        camera, centre, z, _, _ = self._draft
        self._draft = None
        if self._draft_item.scene() is not None:
            self._draft_item.scene().removeItem(self._draft_item)
        radius_px, self._draft_radius_px = self._draft_radius_px, 0.0
        radius = radius_px * z / float(self.shown[camera].frame.K[1, 1])
        if radius < 0.01:
            self.message.emit("Drag out the region's radius (at least 1 cm)")
            return None
        region = Region(centre, radius)
        self.region_drawn.emit(region)
        return region


def _depth_near(depth: np.ndarray, u: int, v: int, reach: int = 4) -> float | None:
    """The depth at pixel (u, v), or the median of the valid ones within ``reach`` pixels."""
    h, w = depth.shape
    if not (0 <= u < w and 0 <= v < h):
        return None
    patch = depth[max(v - reach, 0) : v + reach + 1, max(u - reach, 0) : u + reach + 1]
    if np.isfinite(depth[v, u]):
        return float(depth[v, u])
    valid = patch[np.isfinite(patch)]
    return float(np.median(valid)) if valid.size else None
