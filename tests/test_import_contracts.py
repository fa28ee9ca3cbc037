"""The dependency direction, as import-linter contracts (``[tool.importlinter]`` in pyproject).

``lint-imports`` checks every import statement, lazy ones inside functions and those under
``if TYPE_CHECKING:`` included: instructor_app -> capabilities -> engine, never back; engine
imports no Qt, no robot or vision library; capabilities no Qt; resources nothing of ours; the
simulated and the real cell do not import each other, operations import neither, and the GUI
gets a Cell without importing a backend.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_LINT = "from importlinter.cli import lint_imports_command; lint_imports_command()"


def _lint_imports(root: Path, config: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(root)}
    return subprocess.run(
        [sys.executable, "-c", _LINT, "--config", str(config), "--no-cache"],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )


def test_the_import_contracts_are_kept() -> None:
    result = _lint_imports(ROOT, ROOT / "pyproject.toml")
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_lazy_import_breaks_a_contract(tmp_path: Path) -> None:
    """The project's own layers contract, on a sample tree whose engine imports upward inside
    a function.
    """
    settings = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    layers = next(c for c in settings["tool"]["importlinter"]["contracts"] if c["type"] == "layers")
    for package in layers["layers"]:
        (tmp_path / package).mkdir()
        (tmp_path / package / "__init__.py").write_text("", encoding="utf-8")
    (tmp_path / "engine" / "tree.py").write_text(
        "def f():\n    from capabilities import base\n", encoding="utf-8"
    )
    (tmp_path / "capabilities" / "base.py").write_text("", encoding="utf-8")
    packages = ", ".join(f'"{p}"' for p in layers["layers"])
    config = tmp_path / "pyproject.toml"
    config.write_text(
        f"[tool.importlinter]\nroot_packages = [{packages}]\n\n"
        f'[[tool.importlinter.contracts]]\nname = "layers"\ntype = "layers"\n'
        f"layers = [{packages}]\n",
        encoding="utf-8",
    )
    result = _lint_imports(tmp_path, config)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "engine.tree -> capabilities.base" in result.stdout
