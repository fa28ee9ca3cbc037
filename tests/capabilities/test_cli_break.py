"""``costar run --break``: the run pauses at a node, takes commands from stdin, goes on."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

from capabilities.break_console import BreakpointNotFound, find_node
from capabilities.cli import main

ROOT = Path(__file__).resolve().parents[2]
FIGURE3 = ROOT / "resources" / "examples" / "figure3_debug.costar.json"
MOVE = "cup to bin/transfer or wait[1]/transfer[0]/move to CUP_POSE[3]"


def costar_run(stdin: str, *options: str) -> subprocess.CompletedProcess[str]:
    """``costar run`` of Figure 3 on no cell, its commands fed on stdin."""
    argv = [sys.executable, "-m", "capabilities.cli", "run", "--cell", "none", str(FIGURE3)]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [*argv, "--rate", "200", "--no-record", *options],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
        cwd=ROOT,
    )


def test_it_pauses_before_the_node_prints_and_sets_a_parameter_and_goes_on() -> None:
    commands = [
        "print CUP_POSE",
        "set CUP_POSE 500, 100, 200, 180, 0, 90",
        "set CUP_POSE nonsense",
        "print CUP_POSE",
        "next",
        "continue",
    ]
    proc = costar_run("\n".join(commands) + "\n", "--break", MOVE)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == f"paused before {MOVE}: breakpoint before move to CUP_POSE"
    assert "CUP_POSE = (550.0, -100.0, 50.0) mm, rpy (180.0, 0.0, 0.0)°" in lines
    assert lines.count("CUP_POSE = (500.0, 100.0, 200.0) mm, rpy (180.0, 0.0, 90.0)°") == 2
    assert any("CUP_POSE (Pose) not set: expected x, y, z in mm" in line for line in lines)
    assert f"paused after {MOVE}: step: move to CUP_POSE is SUCCESS" in lines  # next
    assert "SUCCESS after" in proc.stdout


def test_a_path_without_indices_quit_stops_the_run() -> None:
    proc = costar_run("quit\n", "--break", "cup to bin/transfer or wait/transfer/grasp")
    assert proc.returncode == 3, proc.stderr
    assert "paused before cup to bin/transfer or wait[1]/transfer[0]/grasp[4]" in proc.stdout
    assert "stopped after" in proc.stdout


def test_the_end_of_the_input_continues_and_a_step_pauses_at_the_next_change() -> None:
    proc = costar_run("step\n", "--break-after", MOVE)
    assert proc.returncode == 0, proc.stderr
    assert f"paused after {MOVE}: breakpoint after move to CUP_POSE" in proc.stdout
    assert "paused after cup to bin/transfer or wait[1]/transfer[0]/grasp[4]: step:" in (
        proc.stdout
    )
    assert "end of input: continuing" in proc.stdout


def test_a_path_that_names_no_node_exits_2() -> None:
    out, err = io.StringIO(), io.StringIO()
    code = main(["run", "--cell", "none", str(FIGURE3), "--break", "cup to bin/fly"], out, err)
    assert code == 2
    assert "no node has the path 'cup to bin/fly'" in err.getvalue()


def test_find_node_by_id_path_or_bare_path() -> None:
    paths = {"r": "top", "a": "top/pick[0]", "b": "top/pick[1]", "c": "top/place[2]"}
    assert find_node(paths, "c") == "c"
    assert find_node(paths, "top/pick[1]") == "b"
    assert find_node(paths, "top/place") == "c"
    with pytest.raises(BreakpointNotFound, match="several nodes"):
        find_node(paths, "top/pick")
