"""The robot's joints and the cameras' thumbnails go into a run's record while the run goes,
from threads of their own.
"""

from __future__ import annotations

import base64
import time
from pathlib import Path

import cv2
import numpy as np

from capabilities.run_sampler import (
    THUMBNAIL_SIZE,
    JointSampler,
    ThumbnailSampler,
    record_samplers,
)
from engine.events import RunFinished, RunStarted
from engine.status import Status
from engine.trace import TraceRecorder, read_trace


class _Arm:
    def __init__(self) -> None:
        self.reads = 0

    def joint_positions(self) -> list[float]:
        self.reads += 1
        if self.reads == 2:
            raise ConnectionError("the controller did not answer")  # skipped, not fatal
        return [0.1 * self.reads] * 6


def test_joints_are_recorded_from_the_start_to_the_end_of_the_run(tmp_path: Path) -> None:
    arm, path = _Arm(), tmp_path / "run.trace.jsonl"
    recorder = TraceRecorder(path)
    sampler = JointSampler(arm, recorder, period=0.01)
    for listener in (recorder, sampler):
        listener(RunStarted(time.monotonic(), "p"))
    deadline = time.monotonic() + 10.0
    while arm.reads < 5 and time.monotonic() < deadline:
        time.sleep(0.01)
    finished = RunFinished(3, Status.SUCCESS, "finished", "", time.monotonic())
    for listener in (sampler, recorder):
        listener(finished)
    assert sampler.wait(10.0)  # the thread ends with the run
    reads = arm.reads
    recorder.note({"event": "joints", "q": [9.0] * 6})  # the record is closed: ignored
    events = read_trace(path).events
    joints = [e for e in events if e["event"] == "joints"]
    assert len(joints) >= 4 and all(len(e["q"]) == 6 for e in joints)
    assert joints[0]["q"][0] == 0.1 and joints[1]["q"][0] == 0.3  # the failed read is skipped
    assert events[-1]["event"] == "finished" and arm.reads == reads
    assert [e["time"] for e in joints] == sorted(e["time"] for e in joints)


class _Frame:
    def __init__(self, rgb: np.ndarray) -> None:
        self.rgb = rgb


class _Camera:
    """A camera with a live preview (as the simulated cell's): a picture of the asked size."""

    def __init__(self) -> None:
        self.sizes: list[tuple[int, int]] = []

    def preview(self, size: tuple[int, int]) -> _Frame:
        self.sizes.append(size)
        rgb = np.zeros((size[1], size[0], 3), np.uint8)
        rgb[:, : size[0] // 2] = (200, 30, 30)  # left half red
        return _Frame(rgb)


class _BigCamera:
    """A camera with only ``capture()`` (a real one): its own, larger picture."""

    def capture(self) -> _Frame:
        return _Frame(np.full((480, 640, 3), 90, np.uint8))


class _BrokenCamera:
    def capture(self) -> _Frame:
        raise ConnectionError("the camera is unplugged")


def test_a_thumbnail_of_each_camera_goes_into_the_record(tmp_path: Path) -> None:
    path = tmp_path / "run.trace.jsonl"
    recorder = TraceRecorder(path)
    live = _Camera()
    cameras = {"wrist": live, "shoulder": _BigCamera(), "side": _BrokenCamera()}
    sampler = ThumbnailSampler(cameras, recorder, period=0.01)
    for listener in (recorder, sampler):
        listener(RunStarted(time.monotonic(), "p"))
    deadline = time.monotonic() + 10.0
    while len(live.sizes) < 3 and time.monotonic() < deadline:
        time.sleep(0.01)
    finished = RunFinished(3, Status.SUCCESS, "finished", "", time.monotonic())
    for listener in (sampler, recorder):
        listener(finished)
    assert sampler.wait(10.0)
    assert live.sizes[0] == THUMBNAIL_SIZE  # the live view renders it small: nothing to shrink
    assert sampler.failures == {"side": "the camera is unplugged"}  # the others go on
    thumbnails = [e for e in read_trace(path).events if e["event"] == "thumbnail"]
    assert {e["camera"] for e in thumbnails} == {"wrist", "shoulder"}
    assert len(thumbnails) >= 4
    for event in thumbnails:
        data = np.frombuffer(base64.b64decode(event["jpeg"]), np.uint8)
        picture = cv2.imdecode(data, cv2.IMREAD_COLOR)  # BGR
        assert picture.shape == (120, 160, 3)
        if event["camera"] == "wrist":
            assert picture[60, 20, 2] > 150 and picture[60, 140, 2] < 60  # red left, dark right


def test_the_samplers_of_a_cell_follow_its_interfaces(tmp_path: Path) -> None:
    recorder = TraceRecorder(tmp_path / "run.trace.jsonl")
    kinds = [type(s) for s in record_samplers(None, recorder)]
    assert kinds == []

    class _Cell:
        def interfaces(self) -> dict[str, object]:
            return {"arm": _Arm(), "rgbd:wrist": _Camera(), "gripper": object()}

    kinds = [type(s) for s in record_samplers(_Cell(), recorder)]
    assert kinds == [JointSampler, ThumbnailSampler]
    recorder.close()
