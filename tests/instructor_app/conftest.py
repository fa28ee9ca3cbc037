"""Fixtures of the Instructor's tests: a cell session without a robot or with the simulated
one, temporary settings and recovery folders, and dialogs that answer without a person.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from PySide6.QtCore import QSettings

from instructor_app.runtime.session import CellSession
from instructor_app.settings import AppSettings

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


@pytest.fixture
def figure3_path() -> Path:
    return EXAMPLES / "figure3_debug.costar.json"


@pytest.fixture
def fast_sim(qapp: object) -> Iterator[CellSession]:
    """The simulated cell, as fast as possible (for the tests in ``sim`` folders)."""
    session = CellSession("sim", speed=None)
    assert session.open(), "the simulated cell did not open"
    yield session
    session.close()


@pytest.fixture
def none_session(qapp: object) -> Iterator[CellSession]:
    """The "none" cell: only cell-free capabilities (debug) are available."""
    session = CellSession("none")
    session.open()
    yield session
    session.close()


@pytest.fixture
def app_settings(tmp_path: Path) -> AppSettings:
    """Settings in a temporary INI file, never the user's."""
    return AppSettings(QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat))


@pytest.fixture
def recovery_dir(tmp_path: Path) -> Path:
    folder = tmp_path / "recovery"
    folder.mkdir()
    return folder
