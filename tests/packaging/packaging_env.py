"""Helpers of the packaging tests (a module with a unique name, so tests import it whatever
other conftest files are loaded): the sources as a clone has them, offline pip, and fresh
environments that reuse this environment's dependencies (no download of Open3D and the like).
"""

from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def source_files() -> list[str]:
    """The repository's files as a clone would have them (tracked and new, not ignored)."""
    listed = subprocess.run(
        ["git", "-C", str(REPO_ROOT), "ls-files", "--cached", "--others", "--exclude-standard"],
        capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    return [name for name in listed.splitlines() if (REPO_ROOT / name).is_file()]


def pip(*argv: str) -> None:
    """This environment's pip, offline: it builds and installs, it never downloads."""
    subprocess.run(
        [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q", *argv, "--no-index"],
        check=True, capture_output=True, text=True,
    )  # fmt: skip


def lend_dependencies(venv: Path) -> None:
    """Let ``venv`` import this environment's installed dependencies (a .pth line).

    Only the folder is added: the .pth files inside it (this checkout's editable install)
    are not processed, so the application itself comes from what ``venv`` installed.
    """
    (site_packages,) = venv.glob("lib/python3*/site-packages")
    lines = [path for path in site.getsitepackages() if Path(path).is_dir()]
    (site_packages / "_costar_test_dependencies.pth").write_text("\n".join(lines) + "\n")


def fresh_venv(folder: Path) -> Path:
    """A new virtual environment without pip (this environment's pip installs into it)."""
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder)], check=True)
    return folder


def clean_env(**extra: str) -> dict[str, str]:
    """The environment without this checkout on PYTHONPATH (the installed copy must do)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTEST_XDIST_WORKER")}
    env.update(extra)
    return env


def build_wheel(source: Path, dist: Path) -> Path:
    """Copy the sources into ``source`` (so no build/ litters the repository), build the wheel
    into ``dist`` and return it.
    """
    for name in source_files():
        (source / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPO_ROOT / name, source / name)
    pip("wheel", "--no-deps", "--no-build-isolation", "-w", str(dist), str(source))
    (wheel,) = dist.glob("costar_instructor-*.whl")
    return wheel
