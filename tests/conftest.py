"""Marks tests by folder (gui, sim, hardware) so that runs can pick them (-m "not sim")."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# Qt tests run without a screen unless a display (Xvfb) is there for GL views.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen" if not os.environ.get("DISPLAY") else "xcb")

_MARK_BY_FOLDER = {
    "instructor_app": "gui",
    "sim": "sim",
    "hardware": "hardware",
}


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        parts = Path(str(item.fspath)).parts
        for folder, mark in _MARK_BY_FOLDER.items():
            if folder in parts:
                item.add_marker(getattr(pytest.mark, mark))
