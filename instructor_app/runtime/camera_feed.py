"""Live frames of the cell's RGB-D cameras for the GUI, captured on a thread of their own.

A camera's ``capture()`` blocks its caller while the cell renders (in simulation the physics
thread renders with pybullet's CPU renderer), so neither the GUI thread nor the engine's may
call it. :class:`CameraFeed` runs one daemon thread that captures the cameras it is asked for
at a target rate, draws the overlays (:mod:`instructor_app.runtime.overlays`) and leaves one
:class:`FeedFrame` per camera in a latest-frame slot. The GUI thread polls :meth:`latest`
from a timer, as it drains the event pump: frames it did not get to are coalesced away (only
the newest is kept), so a slow GUI never queues frames and never slows the capture.
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
    """Captures cameras on a background thread; the newest frame of each waits in a slot.

    Args:
        cameras: name -> camera interface (``capture() -> RGBDFrame``), e.g. the cell's
            ``rgbd:shoulder`` and ``rgbd:wrist``.
        painter: draws detections, markers and regions into the pictures (None: none).
        fps: the target rate of each camera.
        max_duty: the largest share of wall time spent capturing: after a capture that took
            d seconds the next waits at least d * (1 / max_duty - 1). A simulated camera
            renders on the physics thread (and holds Python's GIL while it does), so this
            keeps the simulation and the engine's ticks going when rendering is slow.
        size: (width, height) to capture at, for cameras whose ``capture`` takes a ``size``
            (a smaller preview renders faster); others give their own size.
        clock: monotonic seconds (tests may pass their own).
    """

    def __init__(
        self,
        cameras: Mapping[str, Any],
        painter: OverlayPainter | None = None,
        fps: float = 15.0,
        size: tuple[int, int] | None = (320, 240),
        max_duty: float = 0.3,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.cameras = dict(cameras)
        self.size = size
        self.max_duty = max_duty
        self.painter = painter
        self.fps = fps
        self._clock = clock
        self._slots: dict[str, FeedFrame] = {}
        self._active: frozenset[str] = frozenset(self.cameras)
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.errors = 0  # captures that raised (the cell closed, a camera failed)

    # ------------------------------------------------------------------ control (any thread)

    def start(self) -> None:
        if self._thread is None and self.cameras:
            self._thread = threading.Thread(target=self._run, name="camera-feed", daemon=True)
            self._thread.start()

    def stop(self, timeout: float = 2.0) -> None:
        """Stop capturing and wait for the thread (a capture in progress finishes first)."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def set_active(self, names: set[str] | frozenset[str]) -> None:
        """Capture only these cameras (none: the thread sleeps and the cell renders nothing)."""
        self._active = frozenset(n for n in names if n in self.cameras)
        self._wake.set()

    @property
    def active(self) -> frozenset[str]:
        return self._active

    def latest(self, name: str) -> FeedFrame | None:
        """The newest frame of a camera (a plain read of a slot: no lock, no wait)."""
        return self._slots.get(name)

    # ------------------------------------------------------------------ the thread

    def _run(self) -> None:
        next_due: dict[str, float] = {}
        seq: dict[str, int] = {}
        not_before = 0.0
        while not self._stop.is_set():
            active = sorted(self._active)
            if not active:
                self._wake.wait(0.5)
                self._wake.clear()
                continue
            period = 1.0 / max(self.fps, 0.1)
            now = self._clock()
            name = min(active, key=lambda n: next_due.get(n, 0.0))
            wait = max(next_due.get(name, 0.0), not_before) - now
            if wait > 0:
                self._wake.wait(wait)
                self._wake.clear()
                continue
            # Due again one period after it was due, not after it finished: the rate holds
            # while a capture takes a good part of the period; a late camera does not burst.
            next_due[name] = max(next_due.get(name, now) + period, now)
            seq[name] = seq.get(name, 0) + 1
            started = self._clock()
            self._capture(name, seq[name])
            took = self._clock() - started
            not_before = self._clock() + took * (1.0 / max(self.max_duty, 0.01) - 1.0)

    def _capture(self, name: str, seq: int) -> None:
        try:
            camera = self.cameras[name]
            sized = self.size is not None and "size" in inspect.signature(camera.capture).parameters
            frame = camera.capture(size=self.size) if sized else camera.capture()
        except Exception as exc:  # a closed cell or a failing camera must not end the feed
            self.errors += 1
            _log.debug("camera %s: %s", name, exc)
            self._stop.wait(0.5)
            return
        rgb = np.array(frame.rgb, dtype=np.uint8, copy=True)
        depth = depth_image(frame.depth)
        if self.painter is not None:
            try:
                self.painter.paint(frame, rgb, depth)
            except Exception:  # an overlay bug shows a plain picture, never ends the feed
                _log.exception("drawing the overlays of camera %s failed", name)
        self._slots[name] = FeedFrame(frame, rgb, depth, seq)
