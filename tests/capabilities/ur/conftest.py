"""Fixtures for the UR cell: a loopback emulator per test (its own process) and ur_rtde clients."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest

from capabilities.ur.arm import URArm
from capabilities.ur.connection import URConnection
from capabilities.ur_emulator.process import EmulatorProcess
from engine.types import Pose
from tests.capabilities.ur.emulators import HOME, next_host


@pytest.fixture
def start_emulator() -> Iterator[Callable[..., EmulatorProcess]]:
    """Start emulators (version "5.12" unless asked); all are closed after the test."""
    started: list[EmulatorProcess] = []

    def start(version: str = "5.12", **options: Any) -> EmulatorProcess:
        options.setdefault("unlock_delay", 0.0)
        emulator = EmulatorProcess(next_host(), version, **options).start()
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
