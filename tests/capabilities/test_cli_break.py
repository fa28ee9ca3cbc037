"""``costar run --break``: the run pauses at a node, takes commands from stdin, goes on."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from capabilities.break_console import BreakpointNotFound, find_node
from capabilities.cli import main
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType

ROOT = Path(__file__).resolve().parents[2]
FIGURE3 = ROOT / "resources" / "examples" / "figure3_debug.costar.json"
MOVE = "cup to bin/transfer or wait[1]/transfer[0]/move to CUP_POSE[3]"


def costar_run(
    stdin: str, *options: str, plan: str = str(FIGURE3)
) -> subprocess.CompletedProcess[str]:
    """``costar run`` of a plan (Figure 3) on no cell, its commands fed on stdin."""
    argv = [sys.executable, "-m", "capabilities.cli", "run", "--cell", "none", plan]
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


def _counting_plan(tmp_path: Path) -> str:
    """A plan that sets count to 0, then three times adds 1 to it and works."""
    script = NodeKind.SCRIPT

    def code(name: str, text: str) -> NodeSpec:
        return NodeSpec(script, name=name, params={"code": Binding.fixed(text, ParamType.TEXT)})

    work = NodeSpec(NodeKind.OPERATION, name="work", op="debug.succeed")
    body = NodeSpec(NodeKind.SEQUENCE, name="once", children=[code("count", "count += 1"), work])
    three = NodeSpec(
        NodeKind.REPEAT,
        name="three times",
        params={"count": Binding.fixed(3.0, ParamType.NUMBER)},
        children=[body],
    )
    top = NodeSpec(NodeKind.SEQUENCE, name="top", children=[code("start", "count := 0"), three])
    path = tmp_path / "count.costar.json"
    save_plan(PlanSpec(top, "count"), path)
    return str(path)


def test_break_if_stops_only_when_its_condition_is_true(tmp_path: Path) -> None:
    plan = _counting_plan(tmp_path)
    where = "top/three times/once/work"
    proc = costar_run("print count\ncontinue\n", "--break-if", where, "count == 2", plan=plan)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("paused before") == 1
    assert "breakpoint before work (count == 2 is true)" in proc.stdout
    assert "count = 2" in proc.stdout
    bad = costar_run("", "--break-if", where, "count ==", plan=plan)
    assert bad.returncode == 2 and "--break-if" in bad.stderr


def test_ctrl_c_while_paused_stops_the_run_without_waiting_for_a_line() -> None:
    argv = [sys.executable, "-m", "capabilities.cli", "run", "--cell", "none", str(FIGURE3)]
    proc = subprocess.Popen(
        [*argv, "--rate", "200", "--no-record", "--break", MOVE],
        stdin=subprocess.PIPE,  # kept open: nothing is typed
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        cwd=ROOT,
    )
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline().startswith(f"paused before {MOVE}")
        proc.send_signal(signal.SIGINT)
        rest, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 3, err
    assert "stopped after" in rest
