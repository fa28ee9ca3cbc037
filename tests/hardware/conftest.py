"""Tests on a real cell (the folder marks them ``hardware``); never run in CI.

They need the real thing, named in the environment:

- ``COSTAR_HARDWARE_CELL``: a cell file whose robot is a real UR (``"kind": "ur"``). The arm
  moves a few degrees at its wrist: clear the space around it and keep the pendant at hand.
- ``COSTAR_REALSENSE``: ``1`` (the only RealSense connected) or a serial number.

Without them the tests are skipped with that reason (``-ra`` lists it).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from typing import Any

import pytest


def _needs(variable: str) -> str:
    value = os.environ.get(variable, "")
    if not value:
        pytest.skip(f"needs a real cell: set {variable} (see tests/hardware/conftest.py)")
    return value


@pytest.fixture
def real_cell() -> Iterator[Any]:
    from capabilities.cells import open_cell

    with open_cell(_needs("COSTAR_HARDWARE_CELL")) as cell:
        yield cell


@pytest.fixture
def realsense_serial() -> str:
    value = _needs("COSTAR_REALSENSE")
    return "" if value == "1" else value
