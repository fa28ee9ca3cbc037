"""Fixtures for the UR cell: a loopback emulator per test (its own process) and ur_rtde clients.

The controller ports are fixed (29999, 30003, 30004), so every emulator gets its own loopback
address: 127.0.<20 + xdist worker>.<counter>.
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable, Iterator

import pytest

from capabilities.ur.arm import URArm
from capabilities.ur.connection import URConnection, URState
from capabilities.ur.emulator.process import EmulatorProcess
from engine.types import Pose

_COUNTER = itertools.count(2)
HOME = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)


def next_host() -> str:
    """A loopback address no other test of this session (or worker) uses."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return f"127.0.{20 + index}.{next(_COUNTER) % 250 + 2}"


def wait_for(predicate: Callable[[], bool], timeout: float = 10.0) -> bool:
    """Poll ``predicate`` until it holds or ``timeout`` real seconds pass (a bounded wait)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


@pytest.fixture
def start_emulator() -> Iterator[Callable[..., EmulatorProcess]]:
    """Start emulators (version "5.12" unless asked); all are closed after the test."""
    started: list[EmulatorProcess] = []

    def start(version: str = "5.12") -> EmulatorProcess:
        emulator = EmulatorProcess(next_host(), version, unlock_delay=0.0).start()
        started.append(emulator)
        return emulator

    yield start
    for emulator in started:
        emulator.close()


@pytest.fixture
def connect() -> Iterator[Callable[[EmulatorProcess], tuple[URConnection, URArm]]]:
    """Open a URConnection and a URArm on an emulator; closed after the test."""
    opened: list[URConnection] = []

    def open_arm(emulator: EmulatorProcess) -> tuple[URConnection, URArm]:
        connection = URConnection(emulator.host)
        opened.append(connection)
        connection.open()
        return connection, URArm(connection, Pose(), Pose(), HOME)

    yield open_arm
    for connection in opened:
        connection.close()


def state_of(connection: URConnection) -> URState:
    return connection.state
