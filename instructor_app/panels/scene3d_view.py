"""The 3D scene's GL view: orbit, pan and zoom (pyqtgraph's GL view), plus what a click
means: a pick ray, a region drawn by press-and-drag, and the tool gizmo's drag.

The view is a window of its own (a QOpenGLWindow with pyqtgraph's ``GLViewMixin``, what its
``GLViewWidget`` is made of), put in the panel by ``QWidget.createWindowContainer``. A
QOpenGLWidget would make Qt compose the whole main window with OpenGL on every repaint of
anything in it (a camera picture, a node's status) as well as every 3D frame: with Mesa's
llvmpipe under Xvfb that cost ~15 ms of CPU per repaint of a 1920 x 1080 window (measured:
18 ms per 3D frame as a widget, 3 ms as a window of its own). Its pictures come from
:meth:`SceneView.grabFramebuffer` (a widget's ``grab`` does not see a native child window).

Mouse: left drag orbits, middle drag (or Ctrl + left) pans, the wheel zooms (pyqtgraph's
own); a left click without a drag picks a point; in region mode a left press sets the centre
and the drag its radius; Shift + left drag on the gizmo's ball moves the gizmo in the plane
facing the view, and so does a plain left drag on it while ``hand_guiding`` is on (Freedrive
on: the tool is taken by hand; a plain drag away from the ball still orbits).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pyqtgraph.opengl.GLViewWidget import GLViewMixin
from PySide6.QtCore import QRect, Qt, Signal
from PySide6.QtOpenGL import QOpenGLWindow

__all__ = ["OpenGLUnavailable", "SceneView", "opengl_problem"]

_CLICK_SLOP_PX = 4.0  # a press and release closer than this is a click, not a drag
_GIZMO_GRAB_PX = 18.0  # how near the gizmo's ball a press must be to grab it


class OpenGLUnavailable(RuntimeError):
    """No OpenGL context can be made here."""


def opengl_problem() -> str | None:
    """Why no OpenGL context can be made on this display (None: it can)."""
    from PySide6.QtGui import QGuiApplication, QOffscreenSurface, QOpenGLContext

    platform = QGuiApplication.platformName()
    if platform in ("offscreen", "minimal"):
        return f"the Qt platform {platform!r} has no OpenGL"
    context = QOpenGLContext()
    if not context.create():
        return "no OpenGL context could be created (no GL driver?)"
    surface = QOffscreenSurface()
    surface.create()
    ok = context.makeCurrent(surface)
    if ok:
        context.doneCurrent()
    return None if ok else "an OpenGL context could not be made current"


# Views alive in Qt. The panel's window container deletes its view (in C++); PySide leaves a
# window made in Python owned by Python all the same, and a view Python deleted first leaves
# the container a dangling window (a crash when the main window is destroyed): Python keeps
# each view until Qt destroys it.
_LIVE: set[SceneView] = set()


class SceneView(GLViewMixin, QOpenGLWindow):
    """pyqtgraph's GL view as a window (see the module's text) that turns clicks into rays
    and counts the frames it draws.

    Signals:
        clicked(object, object): a plain click: (origin, direction) of the pick ray.
        pressed(object, object), dragged(object, object), released(object, object): the
            ray at a left press, each move and the release, while ``capture_drags`` is on
            (region mode).
        gizmo_moved(object, bool): the gizmo's new position (3,) and whether the drag ended.
    """

    clicked = Signal(object, object)
    pressed = Signal(object, object)
    dragged = Signal(object, object)
    released = Signal(object, object)
    gizmo_moved = Signal(object, bool)

    def __init__(self) -> None:
        super().__init__()
        _LIVE.add(self)
        self.destroyed.connect(lambda *_: _LIVE.discard(self))
        self.frames_drawn = 0
        self.capture_drags = False
        self.hand_guiding = False  # a plain left press on the gizmo grabs it (Freedrive on)
        self.gizmo_position: Callable[[], np.ndarray | None] = lambda: None
        self._press: tuple[float, float] | None = None
        self._moved = False
        self._gizmo_drag: np.ndarray | None = None  # the plane's normal while dragging

    def paintGL(self) -> None:
        super().paintGL()
        self.frames_drawn += 1

    # What pyqtgraph's mixin and items ask of a widget, for a window:
    def devicePixelRatioF(self) -> float:
        return float(self.devicePixelRatio())

    def rect(self) -> QRect:
        return QRect(0, 0, self.width(), self.height())

    # ------------------------------------------------------------------ geometry

    def _matrix(self) -> np.ndarray:
        region = self.getViewport()
        m = self.projectionMatrix(region, region) * self.viewMatrix()
        return np.array(m.data(), dtype=float).reshape(4, 4).T

    def ray(self, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
        """(origin, unit direction) in the world of the ray through widget pixel (x, y)."""
        _, _, w, h = self.getViewport()
        ndc = (2.0 * x / max(w, 1) - 1.0, 1.0 - 2.0 * y / max(h, 1))
        inv = np.linalg.inv(self._matrix())
        near = inv @ np.array([ndc[0], ndc[1], -1.0, 1.0])
        far = inv @ np.array([ndc[0], ndc[1], 1.0, 1.0])
        a, b = near[:3] / near[3], far[:3] / far[3]
        return a, (b - a) / np.linalg.norm(b - a)

    def to_screen(self, point: np.ndarray) -> tuple[float, float] | None:
        """Widget pixel of a world point (None behind the eye)."""
        clip = self._matrix() @ np.append(np.asarray(point, dtype=float), 1.0)
        if clip[3] <= 1e-9:
            return None
        _, _, w, h = self.getViewport()
        return (clip[0] / clip[3] + 1.0) * w / 2.0, (1.0 - clip[1] / clip[3]) * h / 2.0

    # ------------------------------------------------------------------ mouse

    def mousePressEvent(self, ev: Any) -> None:
        pos = ev.position()
        self._press, self._moved = (pos.x(), pos.y()), False
        if ev.button() == Qt.MouseButton.LeftButton:
            shift = bool(ev.modifiers() & Qt.KeyboardModifier.ShiftModifier)
            if (shift or self.hand_guiding) and self._grab_gizmo(pos.x(), pos.y()):
                return
            if self.capture_drags:
                self.pressed.emit(*self.ray(pos.x(), pos.y()))
                return
        super().mousePressEvent(ev)

    def mouseMoveEvent(self, ev: Any) -> None:
        pos = ev.position()
        if (
            self._press is not None
            and np.hypot(pos.x() - self._press[0], pos.y() - self._press[1]) > _CLICK_SLOP_PX
        ):
            self._moved = True
        if self._gizmo_drag is not None:
            self._drag_gizmo(pos.x(), pos.y(), done=False)
            return
        if self.capture_drags and ev.buttons() & Qt.MouseButton.LeftButton:
            self.dragged.emit(*self.ray(pos.x(), pos.y()))
            return
        super().mouseMoveEvent(ev)

    def mouseReleaseEvent(self, ev: Any) -> None:
        pos = ev.position()
        if self._gizmo_drag is not None:
            self._drag_gizmo(pos.x(), pos.y(), done=True)
            self._gizmo_drag = None
        elif self.capture_drags and ev.button() == Qt.MouseButton.LeftButton:
            self.released.emit(*self.ray(pos.x(), pos.y()))
        elif ev.button() == Qt.MouseButton.LeftButton and not self._moved:
            self.clicked.emit(*self.ray(pos.x(), pos.y()))
        self._press = None
        super().mouseReleaseEvent(ev)

    def _grab_gizmo(self, x: float, y: float) -> bool:
        centre = self.gizmo_position()
        seen = self.to_screen(centre) if centre is not None else None
        if seen is None or np.hypot(seen[0] - x, seen[1] - y) > _GIZMO_GRAB_PX:
            return False
        _, direction = self.ray(x, y)
        self._gizmo_drag = direction
        return True

    def _drag_gizmo(self, x: float, y: float, done: bool) -> None:
        centre = self.gizmo_position()
        if centre is None or self._gizmo_drag is None:
            return
        origin, direction = self.ray(x, y)
        normal = self._gizmo_drag
        denom = float(np.dot(direction, normal))
        if abs(denom) < 1e-9:
            return
        t = float(np.dot(centre - origin, normal)) / denom
        if t > 0:
            self.gizmo_moved.emit(origin + t * direction, done)
