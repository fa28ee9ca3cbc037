"""The camera feed without a cell: captures on its own thread, keeps only the newest frame,
captures nothing while inactive, and survives a failing camera; projection helpers.
"""

from __future__ import annotations

import threading
import time

import numpy as np

from engine.types import Pose
from instructor_app.runtime.camera_feed import CameraFeed
from instructor_app.runtime.overlays import depth_image, project, unproject


class FakeFrame:
    def __init__(self, n: int) -> None:
        self.rgb = np.full((24, 32, 3), n % 255, np.uint8)
        self.depth = np.full((24, 32), 1.0, np.float32)
        self.K = np.array([[30.0, 0, 16], [0, 30.0, 11], [0, 0, 1]])
        self.T_world_camera = Pose((0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 0.0))  # looking down


class FakeCamera:
    def __init__(self, fail: bool = False) -> None:
        self.calls = 0
        self.threads: set[str] = set()
        self.fail = fail

    def capture(self) -> FakeFrame:
        self.calls += 1
        self.threads.add(threading.current_thread().name)
        if self.fail:
            raise RuntimeError("the cell was closed")
        return FakeFrame(self.calls)


def _wait(condition, timeout: float = 5.0) -> None:
    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.01)


def test_frames_are_captured_off_the_calling_thread_and_only_the_newest_is_kept() -> None:
    camera = FakeCamera()
    feed = CameraFeed({"a": camera}, fps=200.0, max_duty=1.0)
    feed.start()
    try:
        _wait(lambda: (newest := feed.latest("a")) is not None and newest.seq >= 5)
        latest = feed.latest("a")
        assert latest is not None
        assert latest.seq == camera.calls or latest.seq == camera.calls - 1  # one slot, newest
        assert camera.threads == {"camera-feed-a"}
        assert latest.depth.shape == (24, 32, 3) and latest.depth.dtype == np.uint8
    finally:
        feed.stop()


def test_an_inactive_feed_captures_nothing_and_a_failing_camera_does_not_end_it() -> None:
    good, bad = FakeCamera(), FakeCamera(fail=True)
    feed = CameraFeed({"good": good, "bad": bad}, fps=100.0, max_duty=1.0)
    feed.set_active(set())
    feed.start()
    try:
        time.sleep(0.1)
        assert good.calls == 0 and bad.calls == 0
        feed.set_active({"good", "bad"})
        _wait(lambda: feed.errors >= 1 and good.calls >= 3)
        assert feed.running and feed.latest("bad") is None
    finally:
        feed.stop()
    assert not feed.running


def test_project_and_unproject_are_inverse() -> None:
    frame = FakeFrame(0)
    point = np.array([[0.1, -0.05, 0.2]])
    uv, z = project(frame, point)
    assert np.isclose(z[0], 0.8)
    back = unproject(frame, uv[0, 0], uv[0, 1], z[0])
    assert np.allclose(back, point[0])


def test_depth_pictures_are_black_where_there_is_no_depth() -> None:
    depth = np.array([[0.3, np.nan], [1.0, 2.5]], np.float32)
    picture = depth_image(depth)
    assert picture.shape == (2, 2, 3) and picture.dtype == np.uint8
    assert not picture[0, 1].any() and picture[0, 0].any()
