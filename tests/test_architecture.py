"""The dependency direction: instructor_app -> capabilities -> engine, never back.

engine imports no Qt and no robot or vision library; capabilities imports no Qt. Checked on
the source (every import statement), so a lazy import inside a function counts too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

QT = {"PySide6", "PyQt5", "PyQt6", "shiboken6", "NodeGraphQt", "pyqtgraph", "Qt", "OpenGL"}
ROBOT = {"pybullet", "rtde_control", "rtde_receive", "rtde_io", "dashboard_client", "cv2", "open3d"}
FORBIDDEN = {
    "engine": QT | ROBOT | {"capabilities", "instructor_app", "numpy"},
    "capabilities": QT | {"instructor_app"},
}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_package_does_not_import_upward_or_forbidden_libraries(package: str) -> None:
    offenders = []
    files = sorted((ROOT / package).rglob("*.py"))
    assert files, f"no Python files found in {package}/"
    for path in files:
        bad = _imports(path) & FORBIDDEN[package]
        if bad:
            offenders.append(f"{path.relative_to(ROOT)} imports {', '.join(sorted(bad))}")
    assert not offenders, "\n".join(offenders)


def test_the_check_sees_a_forbidden_import(tmp_path: Path) -> None:
    sample = tmp_path / "sample.py"
    sample.write_text("def f():\n    from PySide6 import QtCore\n", encoding="utf-8")
    assert "PySide6" in _imports(sample)


def _modules_imported(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def test_operations_do_not_reach_into_the_simulator() -> None:
    """Only the simulated cell itself (and the cell chooser) may import capabilities.sim: an
    operation that did could read the simulator's ground truth."""
    allowed = {ROOT / "capabilities" / "cells.py"}
    # The UR emulator is a simulator (a UR controller backed by the simulated cell); the UR
    # backends use two stateless helpers that live in sim/ (a command handle, UR5 kinematics).
    simulators = (ROOT / "capabilities" / "sim", ROOT / "capabilities" / "ur" / "emulator")
    helpers = {"capabilities.sim.commands", "capabilities.sim.kinematics"}
    offenders = []
    for path in sorted((ROOT / "capabilities").rglob("*.py")):
        if any(folder in path.parents for folder in simulators) or path in allowed:
            continue
        ur = (ROOT / "capabilities" / "ur") in path.parents
        bad = {
            m
            for m in _modules_imported(path)
            if (m == "capabilities.sim" or m.startswith("capabilities.sim."))
            and not (ur and m in helpers)
        }
        if bad:
            offenders.append(f"{path.relative_to(ROOT)} imports {', '.join(sorted(bad))}")
    assert not offenders, "\n".join(offenders)
