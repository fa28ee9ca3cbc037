"""The simulated cell, as fast as possible: the window's layout with its cameras."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from instructor_app.runtime.session import CellSession


@pytest.fixture
def fast_sim(qapp: Any) -> Iterator[CellSession]:
    session = CellSession("sim", speed=None)
    assert session.open(), "the simulated cell did not open"
    yield session
    session.close()
