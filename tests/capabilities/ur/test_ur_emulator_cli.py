"""``costar ur-emulator`` from the command line: its scene and the cell file it writes agree."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.cells import open_cell
from engine.files import load_plan
from engine.validation import ERROR, validate_plan
from tests.capabilities.ur.emulators import next_host

ROOT = Path(__file__).resolve().parents[3]
VISION_PLAN = ROOT / "resources" / "examples" / "cup_to_bin_vision.costar.json"


def _start(host: str, *options: str) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    args = [sys.executable, "-m", "capabilities.cli", "ur-emulator", "--host", host,
            "--unlock-delay", "0", "--control", "stdin", *options]  # fmt: skip
    return subprocess.Popen(
        args, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env=env, cwd=str(ROOT),
    )  # fmt: skip


def _answer(proc: subprocess.Popen[str]) -> dict[str, object]:
    assert proc.stdout is not None
    line = proc.stdout.readline()
    while line and not line.startswith("{"):  # library banners
        line = proc.stdout.readline()
    assert line, proc.stderr.read() if proc.stderr else "no answer"
    answer: dict[str, object] = json.loads(line)
    return answer


def _quit(proc: subprocess.Popen[str]) -> None:
    assert proc.stdin is not None
    try:
        proc.stdin.write("quit\n")
        proc.stdin.flush()
        proc.wait(timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        proc.kill()
        proc.wait()


@pytest.mark.sim
def test_without_scene_the_emulator_serves_the_default_scene_its_cell_file_lists(
    tmp_path: Path,
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    proc = _start(next_host(), "--write-cell", str(cell_file))
    try:
        assert _answer(proc).get("ok")
        assert proc.stdin is not None
        proc.stdin.write("truth cup\n")  # the simulated cell's default scene has its cup
        proc.stdin.flush()
        assert _answer(proc).get("ok")
        cameras = json.loads(cell_file.read_text(encoding="utf-8"))["cameras"]
        assert cameras["shoulder"]["source"]["kind"] == "stream"
        with open_cell(str(cell_file)) as cell:
            assert "rgbd:shoulder" in cell.interfaces()
            registry = CapabilityRegistry(cell=cell)
            problems = validate_plan(load_plan(VISION_PLAN), registry)
            errors = [str(p) for p in problems if p.severity == ERROR]
            assert not errors, errors
    finally:
        _quit(proc)
