"""A RobotTeacher on the simulated cell (``fast_sim``, from the Instructor's conftest)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from instructor_app.runtime.session import CellSession
from instructor_app.runtime.teach import RobotTeacher


@pytest.fixture
def teacher(fast_sim: CellSession) -> Iterator[RobotTeacher]:
    robot = RobotTeacher(fast_sim.registry, poll_ms=20)
    yield robot
    robot.shutdown()
