"""Marks tests by folder (gui, sim, hardware) so that runs can pick them (-m "not sim")."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# Qt widget tests run on the offscreen platform even under Xvfb: focus and keyboard delivery
# do not depend on a window manager there, so they are deterministic. A test of a GL view
# (which needs Xvfb's GL context) starts its own process with QT_QPA_PLATFORM=xcb.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

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
