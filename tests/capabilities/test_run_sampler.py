"""The robot's joints go into a run's record while the run goes, from a thread of their own."""

from __future__ import annotations

import time
from pathlib import Path

from capabilities.run_sampler import JointSampler
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
