"""Fixtures for the simulated cell tests: a running cell and a way to drop boxes on its table."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from capabilities.sim.cell import SimCell
from capabilities.sim.testing import add_box


@pytest.fixture
def cell() -> Iterator[SimCell]:
    """A started simulated cell with the default config, driven by the test (it steps as fast
    as it can while a command runs or the test waits for simulated time, else stands still:
    the outcome of contacts does not depend on the machine's load).
    """
    sim = SimCell(speed=None, driven=True)
    sim.start()
    try:
        yield sim
    finally:
        sim.close()


@pytest.fixture
def make_box(cell: SimCell) -> Callable[..., int]:
    """``make_box((sx, sy, sz), (x, y), mass=0.2)``: a box resting on the table, settled."""

    def make(size: tuple[float, float, float], xy: tuple[float, float], mass: float = 0.2) -> int:
        body = add_box(cell, size, xy, mass)
        cell.wait_sim(0.2)
        return body

    return make
