"""Live frames of the cell's RGB-D cameras for the GUI, captured on a thread of their own.

A camera's ``capture()`` blocks its caller while the cell renders, so neither the GUI thread
nor the engine's may call it. A camera that also has ``preview(size, ahead)`` (the simulated cell's:
pictures rendered by a mirror of the cell in a process of its own, see
``capabilities/sim/live_view.py``) gives live pictures without holding the cell's physics
thread; any other capture holds the cell and is limited to a share of the time.
:class:`CameraFeed` runs one daemon thread per camera that captures it at a target rate
(cameras rendered in parallel processes come in parallel), draws the overlays (:mod:`instructor_app.runtime.overlays`) and leaves one
:class:`FeedFrame` per camera in a latest-frame slot. The GUI thread polls :meth:`latest`
from a timer, as it drains the event pump: frames it did not get to are coalesced away (only
the newest is kept), so a slow GUI never queues frames and never slows the capture.
A capture that gives the very same picture as the last one (the simulated cell's live view
renders nothing while nothing in view moved) with the same overlays leaves no new frame:
an idle cell makes the GUI draw nothing. ``on_frame`` (if given) is called on the capture
thread whenever a new frame or a failure is left, so that a GUI may sleep until then.
No Qt here.
"""

from __future__ import annotations

import inspect
import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from instructor_app.runtime.overlays import OverlayPainter, depth_image

__all__ = ["CameraFeed", "FeedFrame"]

_log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class FeedFrame:
    """One captured frame and its two pictures with overlays drawn in.

    Attributes:
        frame: the camera's RGBDFrame (colour, metric depth, K, the camera's pose).
        rgb: HxWx3 uint8, the colour image with the overlays.
        depth: HxWx3 uint8, the depth coloured near-to-far with the overlays.
        seq: counts the frames of this camera (the GUI shows a frame once).
    """

    frame: Any
    rgb: np.ndarray
    depth: np.ndarray
    seq: int


class CameraFeed:
    """Captures cameras on background threads; the newest frame of each waits in a slot.

    Args:
        cameras: name -> camera interface (``capture() -> RGBDFrame``), e.g. the cell's
            ``rgbd:shoulder`` and ``rgbd:wrist``.
        painter: draws detections, markers and regions into the pictures (None: none).
        fps: the target rate of each camera.
        max_duty: the largest share of wall time spent in captures that hold the cell (those
            of cameras without ``preview``): after one that took d seconds the next waits at
            least d * (1 / max_duty - 1). A capture rendered on the simulated cell's physics
            thread holds Python's GIL too, so this keeps the simulation and the engine's
            ticks going when rendering is slow.
        size: (width, height) to capture at, for cameras with ``preview(size)`` or whose
            ``capture`` takes a ``size`` (a smaller picture renders faster); others give
            their own size; None: every camera's own size through ``capture()``.
        clock: monotonic seconds (tests may pass their own).
        on_frame: called (on a capture thread) after a new frame or a failure was left.
    """

    def __init__(
        self,
        cameras: Mapping[str, Any],
        painter: OverlayPainter | None = None,
        fps: float = 15.0,
        size: tuple[int, int] | None = (320, 240),
        max_duty: float = 0.3,
        clock: Callable[[], float] = time.perf_counter,
        on_frame: Callable[[], None] | None = None,
    ) -> None:
        self.cameras = dict(cameras)
        self.size = size
        self.max_duty = max_duty
        self.painter = painter
        self.fps = fps
        self._clock = clock
        self.on_frame = on_frame
        self._sources: dict[str, tuple[Any, Any]] = {}  # camera -> (picture, overlay key) shown
        self.unchanged = 0  # captures that gave the same picture and overlays as the last
        self._slots: dict[str, FeedFrame] = {}
        self._active: frozenset[str] = frozenset(self.cameras)
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._cell_lock = threading.Lock()  # one capture that holds the cell at a time
        self._not_before = 0.0  # when the next capture that holds the cell may start
        self.errors = 0  # captures that raised (the cell closed, a camera failed)
        self.failures: dict[str, str] = {}  # camera -> why its last capture failed

    # ------------------------------------------------------------------ control (any thread)

    def start(self) -> None:
        """Start one capture thread per camera (each keeps its own rate)."""
        if self._threads or not self.cameras:
            return
        self._stop.clear()
        for name in sorted(self.cameras):
            thread = threading.Thread(
                target=self._run, args=(name,), name=f"camera-feed-{name}", daemon=True
            )
            self._threads.append(thread)
            thread.start()

    def stop(self, timeout: float = 2.0) -> None:
        """Stop capturing and wait for the threads (a capture in progress finishes first)."""
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout)
        self._threads = []

    @property
    def running(self) -> bool:
        return any(thread.is_alive() for thread in self._threads)

    def set_active(self, names: set[str] | frozenset[str]) -> None:
        """Capture only these cameras (none: the threads sleep and the cell renders nothing)."""
        self._active = frozenset(n for n in names if n in self.cameras)

    @property
    def active(self) -> frozenset[str]:
        return self._active

    def latest(self, name: str) -> FeedFrame | None:
        """The newest frame of a camera (a plain read of a slot: no lock, no wait)."""
        return self._slots.get(name)

    # ------------------------------------------------------------------ the threads

    def _run(self, name: str) -> None:
        camera = self.cameras[name]
        # A camera with ``preview(size, ahead)`` renders its live pictures away from the cell
        # (the simulated cell's mirror process): nothing to spare, it runs at the target rate.
        # ``ahead``: the mirror renders the next frame while this thread draws and waits.
        # Any other capture holds the cell: the duty limit, shared by all such cameras.
        own = self.size is not None and callable(getattr(camera, "preview", None))
        next_due, seq = 0.0, 0
        while not self._stop.is_set():
            if name not in self._active:
                self._stop.wait(0.05)  # asleep: the cell renders nothing for this camera
                continue
            now = self._clock()
            wait = max(next_due, 0.0 if own else self._not_before) - now
            if wait > 0:
                self._stop.wait(min(wait, 0.5))
                continue
            # Due again one period after it was due, not after it finished: the rate holds
            # while a capture takes a good part of the period; a late camera does not burst.
            next_due = max(next_due + 1.0 / max(self.fps, 0.1), now)
            seq += 1
            if own:
                captured = self._capture(name, seq, lambda: camera.preview(self.size, ahead=True))
            else:
                with self._cell_lock:
                    started = self._clock()
                    captured = self._capture(name, seq, lambda: self._plain_capture(camera))
                    took = self._clock() - started
                    self._not_before = self._clock() + took * (1.0 / max(self.max_duty, 0.01) - 1.0)
            if not captured:
                self._stop.wait(0.5)  # a failing camera is asked again later, never in a loop

    def _plain_capture(self, camera: Any) -> Any:
        sized = self.size is not None and "size" in inspect.signature(camera.capture).parameters
        return camera.capture(size=self.size) if sized else camera.capture()

    def _capture(self, name: str, seq: int, grab: Callable[[], Any]) -> bool:
        """Capture one frame and leave it in the camera's slot; False if the capture failed."""
        try:
            frame = grab()
        except Exception as exc:  # a closed cell or a failing camera must not end the feed
            self.errors += 1
            self.failures[name] = str(exc) or type(exc).__name__
            _log.debug("camera %s: %s", name, exc)
            self._notify()
            return False
        failed = self.failures.pop(name, None) is not None
        key = self.painter.state_key() if self.painter is not None else None
        source = self._sources.get(name)
        if source is not None and source[0] is frame.rgb and source[1] == key and not failed:
            self.unchanged += 1  # nothing in view moved and the overlays are the same
            return True
        self._sources[name] = (frame.rgb, key)
        rgb = np.array(frame.rgb, dtype=np.uint8, copy=True)
        depth = depth_image(frame.depth)
        if self.painter is not None:
            try:
                self.painter.paint(frame, rgb, depth)
            except Exception:  # an overlay bug shows a plain picture, never ends the feed
                _log.exception("drawing the overlays of camera %s failed", name)
        self._slots[name] = FeedFrame(frame, rgb, depth, seq)
        self._notify()
        return True

    def _notify(self) -> None:
        if self.on_frame is not None:
            try:
                self.on_frame()
            except Exception:  # e.g. the GUI's object was deleted: the feed goes on
                _log.debug("on_frame failed", exc_info=True)
