"""Fixtures of the Instructor's runtime tests: a loopback UR controller (its own process) that
wrote a cell file into the test's folder.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from capabilities.ur_emulator.process import EmulatorProcess
from tests.capabilities.ur.emulators import next_host


@pytest.fixture
def emulator(tmp_path: Path) -> Iterator[EmulatorProcess]:
    """A UR emulator (PolyScope 5.12, unlocks at once) and ``tmp_path/emulated.cell.json``."""
    process = EmulatorProcess(
        next_host(), "5.12", unlock_delay=0.0, write_cell=tmp_path / "emulated.cell.json"
    )
    with process:
        yield process
