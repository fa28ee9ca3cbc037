"""Marks tests by what they use, so that runs can pick them (-m "not sim").

``gui`` and ``hardware`` go by folder. ``sim`` goes by use: a test is ``sim`` when it, or
any fixture it uses (directly or through other fixtures), starts the simulated cell, that is
names ``SimCellSession``, ``SimCell`` or ``open_cell`` in its code, wherever its file lives.
The ``sim`` folder marks ``sim`` too.
"""

from __future__ import annotations

import os
from pathlib import Path
from types import CodeType
from typing import Any

import pytest

# Qt widget tests run on the offscreen platform even under Xvfb: focus and keyboard delivery
# do not depend on a window manager there, so they are deterministic. A test of a GL view
# (which needs Xvfb's GL context) starts its own process with QT_QPA_PLATFORM=xcb.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

# Under xdist each worker already has a core of its own: a thread pool per worker (Open3D's
# OpenMP, numpy's OpenBLAS) only spins beside the other workers. Measured on kitting seed 3
# alone: 54 CPU s with the pools, 44 without. Set before any test imports those libraries
# (their pools read the variable when they load); subprocesses inherit it.
if os.environ.get("PYTEST_XDIST_WORKER"):
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

_MARK_BY_FOLDER = {
    "instructor_app": "gui",
    "sim": "sim",
    "hardware": "hardware",
}

# Names whose use in a test or fixture means the simulated cell (pybullet) starts.
_STARTS_THE_SIM = frozenset({"SimCellSession", "SimCell", "open_cell"})


def _names(code: CodeType) -> set[str]:
    """Global and attribute names a function's code uses, nested functions included."""
    found = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, CodeType):
            found |= _names(const)
    return found


def _starts_the_sim(func: Any) -> bool:
    code = getattr(getattr(func, "__wrapped__", func), "__code__", None)
    return code is not None and not _STARTS_THE_SIM.isdisjoint(_names(code))


def uses_the_sim(item: pytest.Item) -> bool:
    """True when the test or a fixture in its closure starts the simulated cell."""
    if _starts_the_sim(getattr(item, "function", None)):
        return True
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    return any(
        _starts_the_sim(fixturedef.func)
        for fixturedefs in info.name2fixturedefs.values()
        for fixturedef in fixturedefs
    )


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        parts = Path(str(item.fspath)).parts
        for folder, mark in _MARK_BY_FOLDER.items():
            if folder in parts:
                item.add_marker(getattr(pytest.mark, mark))
        if "sim" not in item.keywords and uses_the_sim(item):
            item.add_marker(pytest.mark.sim)


@pytest.fixture(autouse=True)
def _own_subtree_library(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Tests never read or write the user's subtree library or run records: COSTAR_LIBRARY
    and COSTAR_RUNS are fresh folders.
    """
    monkeypatch.setenv("COSTAR_LIBRARY", str(tmp_path_factory.mktemp("library")))
    monkeypatch.setenv("COSTAR_RUNS", str(tmp_path_factory.mktemp("runs")))
