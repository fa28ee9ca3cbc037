"""The application's wheel, built once per test session (offline, from a copy of the sources)."""

from __future__ import annotations

from pathlib import Path

import pytest
from packaging_env import build_wheel


@pytest.fixture(scope="session")
def built_wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wheel of this checkout."""
    return build_wheel(tmp_path_factory.mktemp("source"), tmp_path_factory.mktemp("dist"))
