"""The simulated cell, as fast as possible, with a RobotTeacher on it."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from instructor_app.runtime.session import CellSession
from instructor_app.runtime.teach import RobotTeacher


@pytest.fixture
def fast_sim(qapp: Any) -> Iterator[CellSession]:
    session = CellSession("sim", speed=None)
    assert session.open(), "the simulated cell did not open"
    yield session
    session.close()


@pytest.fixture
def teacher(fast_sim: CellSession) -> Iterator[RobotTeacher]:
    robot = RobotTeacher(fast_sim.registry, poll_ms=20)
    yield robot
    robot.shutdown()
