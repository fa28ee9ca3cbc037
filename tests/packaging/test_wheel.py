"""The wheel carries every shipped file: installed into a fresh environment in another folder,
``costar run example:cup_to_bin --seed 3`` succeeds there, away from the repository.
"""

from __future__ import annotations

import subprocess
import zipfile
from pathlib import Path

import pytest
from packaging_env import clean_env, fresh_venv, lend_dependencies, pip, source_files


def test_the_wheel_carries_every_shipped_file(built_wheel: Path) -> None:
    """Every file of resources/ (data and its locator, resources/__init__.py; the generators
    live in tools/, which is not shipped): a new kind of file fails here until
    pyproject.toml's package-data lists it.
    """
    names = set(zipfile.ZipFile(built_wheel).namelist())
    shipped = {name for name in source_files() if name.startswith("resources/")}
    assert {"resources/icons/costar-instructor.svg", "resources/objects/cup/cup.obj"} <= shipped
    assert [name for name in shipped if name.endswith(".py")] == ["resources/__init__.py"]
    assert shipped <= names, sorted(shipped - names)
    assert not [name for name in names if name.startswith("tools/")]


@pytest.mark.sim
def test_the_installed_wheel_runs_an_example_from_any_folder(
    built_wheel: Path, tmp_path: Path
) -> None:
    venv = fresh_venv(tmp_path / "venv")
    pip("--python", str(venv / "bin" / "python"), "install", "--no-deps", str(built_wheel))
    lend_dependencies(venv)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = clean_env()

    where = subprocess.run(
        [str(venv / "bin" / "python"), "-c", "import capabilities, resources; "
         "print(capabilities.__file__); print(resources.root())"],
        cwd=elsewhere, env=env, capture_output=True, text=True, check=True,
    ).stdout.split()  # fmt: skip
    assert all(Path(path).is_relative_to(venv) for path in where), where

    done = subprocess.run(
        [str(venv / "bin" / "costar"), "run", "example:cup_to_bin", "--seed", "3", "--fast"],
        cwd=elsewhere, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert "SUCCESS" in done.stdout
    assert sorted(p.name for p in elsewhere.iterdir()) == []  # nothing written where it ran
