"""The repository stands alone: a fresh clone, with nothing beside it, passes the bench tests."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
PYTEST = [sys.executable, "-m", "pytest", "-q", "-p", "no:xdist", "-p", "no:cacheprovider"]


def _committed_clone(destination: Path) -> Path:
    """A ``git clone`` of this repository's committed HEAD into ``destination/repo``."""
    head = subprocess.run(
        ["git", "-C", str(REPO_ROOT), "rev-parse", "HEAD"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    clone = destination / "repo"
    subprocess.run(
        ["git", "clone", "--quiet", "--no-hardlinks", str(REPO_ROOT), str(clone)],
        check=True,
        capture_output=True,
    )
    subprocess.run(
        ["git", "-C", str(clone), "checkout", "--quiet", head], check=True, capture_output=True
    )
    return clone


# The bench tests that read the bench's own data (the trees once read from beside the
# repository) and run every bench command once. The case-study and soak tests read only
# resources/, which the whole suite already runs from a fresh clone in CI, and every file's
# paths are checked below: run here again they cost 38 s of a 5-minute suite.
STANDALONE_TESTS = ["tests/bench/test_engine_ticks.py", "tests/bench/test_bench_cli.py"]


def test_a_clone_in_an_empty_folder_passes_the_bench_tests(tmp_path: Path) -> None:
    clone = _committed_clone(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["repo"]  # no ../shared beside it
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTEST_XDIST_WORKER")}
    result = subprocess.run(
        [*PYTEST, *STANDALONE_TESTS],
        cwd=clone,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    assert " passed" in result.stdout and "skipped" not in result.stdout, result.stdout[-2000:]


def test_no_file_reads_a_path_outside_the_repository() -> None:
    tracked = subprocess.run(
        ["git", "-C", str(REPO_ROOT), "ls-files", "*.py", "*.sh", "*.toml", "*.json", "*.in"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    outside = ("../shared", "/work/", '/ "shared"', "parents[1].parent", "parents[2].parent")
    offenders = []
    for name in tracked:
        if name.startswith("tests/packaging/"):
            continue  # this test names the patterns it looks for
        text = (REPO_ROOT / name).read_text(encoding="utf-8", errors="replace")
        offenders += [f"{name}: {pattern}" for pattern in outside if pattern in text]
    assert offenders == []
