"""``packaging/install.sh`` in a temporary home: the environment, the two commands on the
PATH, the menu entry with its icon; run again it upgrades; ``--uninstall`` removes it all.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from packaging_env import REPO_ROOT, clean_env, lend_dependencies

INSTALL = REPO_ROOT / "packaging" / "install.sh"
# Offline and quick: the wheel of this checkout, no dependencies fetched (they are lent from
# this environment afterwards), no apt.
OFFLINE = ["--user", "--no-system-packages", "--pip-args", "--no-deps --no-index"]


def install(home: Path, *options: str) -> subprocess.CompletedProcess[str]:
    env = clean_env(HOME=str(home), PYTHON=sys.executable)
    env.pop("XDG_DATA_HOME", None)
    return subprocess.run(
        ["bash", str(INSTALL), *options],
        capture_output=True, text=True, timeout=300, env=env, cwd=home,
    )  # fmt: skip


def files_under(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if not p.is_dir())


def test_install_upgrade_and_uninstall_in_a_home(built_wheel: Path, tmp_path: Path) -> None:
    home = tmp_path / "home"
    home.mkdir()
    done = install(home, *OFFLINE, "--from", str(built_wheel))
    assert done.returncode == 0, done.stdout + done.stderr

    share = home / ".local" / "share"
    venv = share / "costar-instructor" / "venv"
    for name in ("costar", "costar-instructor"):
        link = home / ".local" / "bin" / name
        assert link.is_symlink() and link.resolve() == (venv / "bin" / name).resolve()
    desktop = (share / "applications" / "costar-instructor.desktop").read_text()
    icon = share / "icons" / "hicolor" / "scalable" / "apps" / "costar-instructor.svg"
    assert f"Exec={home}/.local/bin/costar-instructor %f" in desktop
    assert f"Icon={icon}" in desktop and icon.read_text().startswith("<?xml")
    assert "add " in done.stdout and ".local/bin to your PATH" in done.stdout

    lend_dependencies(venv)
    listed = subprocess.run(
        [str(home / ".local" / "bin" / "costar"), "examples"],
        capture_output=True, text=True, timeout=120, env=clean_env(), cwd=home,
    )  # fmt: skip
    assert listed.returncode == 0, listed.stderr
    assert "cup_to_bin: " in listed.stdout

    # Run again: the application is put in place again (an upgrade), the links stay.
    (shipped_icon,) = venv.glob("lib/python3*/site-packages/resources/icons/costar-instructor.svg")
    shipped_icon.unlink()
    again = install(home, *OFFLINE, "--from", str(built_wheel))
    assert again.returncode == 0, again.stdout + again.stderr
    assert shipped_icon.is_file()

    gone = install(home, "--user", "--uninstall")
    assert gone.returncode == 0, gone.stderr
    assert files_under(home / ".local") == [], files_under(home / ".local")


def test_dry_run_changes_nothing_and_a_command_not_its_own_is_left(tmp_path: Path) -> None:
    home = tmp_path / "home"
    mine = home / ".local" / "bin" / "costar"
    mine.parent.mkdir(parents=True)
    mine.write_text("#!/bin/sh\necho mine\n")
    done = install(home, "--user", "--dry-run")
    assert done.returncode == 0, done.stderr
    assert "+ ln -sfn" in done.stdout and "pip install" in done.stdout
    assert "costar-instructor.desktop" in done.stdout
    assert f"{mine} exists and is not ours" in done.stderr
    assert f"bin/costar {mine}" not in done.stdout  # not linked over the user's own file
    assert files_under(home / ".local") == ["bin/costar"]

    gone = install(home, "--user", "--uninstall")
    assert gone.returncode == 0, gone.stderr
    assert mine.read_text().endswith("echo mine\n")
