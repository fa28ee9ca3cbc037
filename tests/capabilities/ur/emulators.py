"""Helpers for the UR cell tests: a loopback address per emulator, bounded waits.

The controller ports are fixed (29999, 30003, 30004), so every emulator gets its own loopback
address: 127.<process>.<xdist worker>.<counter>, the process part keeping apart test sessions
that run at the same time on one machine.
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable

__all__ = ["FAST", "HOME", "next_host", "wait_for"]

_COUNTER = itertools.count(2)
HOME = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)
# The emulated cell's real-time factor (EmulatorProcess(speed=...)) for a test whose checks do
# not depend on the arm's pace in wall-clock time: its moves only have to end, and what they
# meet (a collision's force, a grasp) is simulated time. A test that injects a fault while a
# move is under way, or checks how far the arm went before something stopped it (a watchdog,
# a halt, all in real time), keeps the real-time pace.
FAST = 4.0


def next_host() -> str:
    """A loopback address no other test of this session (or worker) uses."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return f"127.{os.getpid() % 200 + 20}.{index}.{next(_COUNTER) % 250 + 2}"


def wait_for(predicate: Callable[[], bool], timeout: float = 10.0) -> bool:
    """Poll ``predicate`` until it holds or ``timeout`` real seconds pass (a bounded wait)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()
