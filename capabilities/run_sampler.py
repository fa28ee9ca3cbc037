"""The robot's joints in a run's record, ten times a second, while the run goes.

A run listener: it starts its own thread when the run starts and ends it when the run ends,
so reading the arm never takes a tick of the engine's or a moment of the event dispatcher's.
Each sample is a ``joints`` record (``q``: the six joint angles in radians) among the run's
events; a replay or a timeline puts the robot where it was.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Protocol

from engine.events import Event, RunFinished, RunStarted
from engine.trace import TraceRecorder

__all__ = ["JointSampler", "SAMPLE_PERIOD_S"]

SAMPLE_PERIOD_S = 0.1


class _Arm(Protocol):
    def joint_positions(self) -> Sequence[float]: ...


class JointSampler:
    """A run listener that writes ``arm``'s joints to ``recorder`` every ``period`` s.

    A read that fails (a controller gone, a cell closing) is skipped, not fatal: the record
    goes on with the run's events.
    """

    def __init__(self, arm: _Arm, recorder: TraceRecorder, period: float = SAMPLE_PERIOD_S) -> None:
        self._arm = arm
        self._recorder = recorder
        self._period = period
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._sample, name="costar-joints", daemon=True)

    def __call__(self, event: Event) -> None:
        if isinstance(event, RunStarted) and not self._thread.is_alive():
            self._thread.start()
        elif isinstance(event, RunFinished):
            self._done.set()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until the sampling thread ended (after the run's end); whether it has."""
        if self._thread.is_alive():
            self._thread.join(timeout)
        return not self._thread.is_alive()

    def _sample(self) -> None:
        while not self._done.is_set():
            try:
                q = [round(float(a), 6) for a in self._arm.joint_positions()]
            except Exception:  # the cell cannot answer now: no sample this time
                q = []
            if q:
                self._recorder.note({"event": "joints", "q": q})
            self._done.wait(self._period)
