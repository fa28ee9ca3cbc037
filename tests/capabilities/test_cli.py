"""The `costar` command line: exit codes, output, traces, Ctrl-C."""

from __future__ import annotations

import io
import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from capabilities.cli import main
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
FIGURE3 = EXAMPLES / "figure3_debug.costar.json"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def _save(tmp_path: Path, tree: NodeSpec, name: str = "plan") -> str:
    path = tmp_path / f"{name}.costar.json"
    save_plan(PlanSpec(tree, name), path)
    return str(path)


def _op(op: str, **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, op=op, params=params)


def test_validate_valid_plan_exits_0() -> None:
    code, out, _ = run_cli("validate", "--cell", "none", str(FIGURE3))
    assert code == 0
    assert "valid" in out


def test_validate_invalid_plan_lists_problems_with_paths_and_exits_2(tmp_path: Path) -> None:
    tree = NodeSpec(
        NodeKind.SEQUENCE,
        "steps",
        children=[
            _op("debug.pretend_move", target=Binding.reference("NOWHERE")),
            _op("debug.no_such_thing"),
        ],
    )
    code, out, _ = run_cli("validate", "--cell", "none", _save(tmp_path, tree))
    assert code == 2
    assert "NOWHERE" in out
    assert "debug.no_such_thing" in out
    assert "steps/" in out  # problems name the node's path


def test_validate_broken_file_exits_2_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "broken.costar.json"
    path.write_text('{"format": "costar-plan", "format_version": 1, "tree": {', encoding="utf-8")
    code, _, err = run_cli("validate", "--cell", "none", str(path))
    assert code == 2
    assert "broken.costar.json" in err


def test_validate_missing_file_exits_2(tmp_path: Path) -> None:
    code, _, err = run_cli("validate", "--cell", "none", str(tmp_path / "nope.costar.json"))
    assert code == 2
    assert "nope.costar.json" in err


def test_run_success_exits_0_and_verbose_prints_status_changes() -> None:
    code, out, _ = run_cli("run", "--cell", "none", str(FIGURE3), "--rate", "200", "--verbose")
    assert code == 0
    assert "RUNNING -> SUCCESS" in out
    assert "CUP_POSE" in out
    summary = out[out.index("SUCCESS after") :].splitlines()
    # The cup is not found twice: those failures, and what carried on past them, are named.
    assert summary[1:4] == [
        "  on the way:",
        "  - CUP found failed 2 times: false; passed up by Sequence 'transfer'; caught by "
        "Selector 'transfer or wait'",
        "  - Force failure 'then try again' failed 2 times: forced failure; passed up by "
        "Selector 'transfer or wait', Sequence 'cup to bin'; caught by the plan's root (runs "
        "until success)",
    ]


def test_run_failure_exits_1_with_the_message(tmp_path: Path) -> None:
    tree = _op("debug.fail", message=Binding.fixed("gripper empty", ParamType.TEXT))
    code, out, _ = run_cli("run", "--cell", "none", _save(tmp_path, tree), "--rate", "100")
    assert code == 1
    assert "FAILURE" in out
    assert "gripper empty" in out


def test_run_skipped_by_its_conditions_exits_0_saying_skipped(tmp_path: Path) -> None:
    from engine.conditions import Condition

    tree = _op("debug.fail", message=Binding.fixed("never", ParamType.TEXT))
    tree.conditions = {Condition.SKIP_IF: "true"}
    code, out, _ = run_cli(
        "run", "--cell", "none", _save(tmp_path, tree), "--rate", "100", "--verbose"
    )
    assert code == 0
    assert "plan: SKIPPED after 1 ticks" in out and "IDLE -> SKIPPED" in out
    trace = tmp_path / "skipped.trace.jsonl"
    plan_file = str(tmp_path / "plan.costar.json")
    assert run_cli("run", "--cell", "none", plan_file, "--trace", str(trace))[0] == 0
    from engine.status import Status
    from engine.trace import read_trace

    read = read_trace(trace)
    assert read.final_status is Status.SKIPPED
    assert "SKIPPED" in read.statuses(tree.id)
    code, out, _ = run_cli("trace", "show", str(trace))
    assert code == 0 and "run finished: SKIPPED" in out


def test_run_invalid_plan_is_not_started_exits_2(tmp_path: Path) -> None:
    code, _, err = run_cli("run", "--cell", "none", _save(tmp_path, _op("debug.pretend_move")))
    assert code == 2
    assert "not started" in err


def test_run_timeout_exits_3(tmp_path: Path) -> None:
    tree = _op("debug.running", ticks=Binding.fixed(10_000, ParamType.NUMBER))
    code, out, _ = run_cli(
        "run", "--cell", "none", _save(tmp_path, tree), "--rate", "100", "--timeout", "0.3"
    )
    assert code == 3
    assert "timeout" in out


def test_run_bad_rate_exits_2() -> None:
    code, _, err = run_cli("run", "--cell", "none", str(FIGURE3), "--rate", "0")
    assert code == 2
    assert "rate" in err


def test_run_writes_a_trace_that_trace_show_reads(tmp_path: Path) -> None:
    trace = tmp_path / "run.trace.jsonl"
    code, _, _ = run_cli(
        "run", "--cell", "none", str(FIGURE3), "--rate", "200", "--trace", str(trace)
    )
    assert code == 0
    code, out, _ = run_cli("trace", "show", str(trace))
    assert code == 0
    assert "move to CUP_POSE: IDLE -> RUNNING" in out
    assert "run finished: SUCCESS" in out


def test_trace_show_bad_file_exits_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.trace.jsonl"
    bad.write_text("not json\n", encoding="utf-8")
    code, _, err = run_cli("trace", "show", str(bad))
    assert code == 2
    assert "bad.trace.jsonl:1" in err


def test_ops_lists_every_operation_with_parameters() -> None:
    code, out, _ = run_cli("ops", "--cell", "none")
    assert code == 0
    assert "debug.running" in out and "ticks: Number" in out


def test_ops_json_has_types_defaults_and_docs() -> None:
    code, out, _ = run_cli("ops", "--cell", "none", "--json")
    assert code == 0
    ops = {entry["id"]: entry for entry in json.loads(out)}
    running = ops["debug.running"]
    assert running["kind"] == "action"
    ticks = next(p for p in running["params"] if p["name"] == "ticks")
    assert ticks["types"] == ["Number"] and ticks["default"] == 3 and ticks["doc"]


def test_unknown_command_exits_2() -> None:
    code, _, _ = run_cli("fly")
    assert code == 2


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_ctrl_c_sigterm_and_sighup_halt_cleanly_and_exit_3(tmp_path: Path, signum: int) -> None:
    tree = _op("debug.running", ticks=Binding.fixed(100_000, ParamType.NUMBER))
    plan = _save(tmp_path, tree)
    trace = tmp_path / "run.trace.jsonl"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "capabilities.cli",
            "run",
            "--cell",
            "none",
            plan,
            "--verbose",
            "--rate",
            "50",
            "--trace",
            str(trace),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()  # the run has started once a status line is printed
        assert "RUNNING" in first
        assert "RUNNING" in trace.read_text()  # written as the run goes, not at its end
        proc.send_signal(signum)
        rest, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 3, err
    assert "RUNNING -> IDLE" in rest  # the running action was halted
    assert "stopped" in rest


@pytest.mark.parametrize("argv", [["--help"], ["run", "--help"]])
def test_help_exits_0(argv: list[str]) -> None:
    code, _, _ = run_cli(*argv)
    assert code == 0


EXPECTED_OPS = {
    "motion.move_to", "motion.move_joints", "motion.move_relative", "motion.go_home", "motion.stop",
    "motion.current_pose", "motion.current_joints", "motion.is_moving", "motion.is_stopped",
    "motion.is_home", "gripper.open", "gripper.close", "gripper.is_closed", "gripper.is_holding",
    "tool.unholster", "tool.holster", "tool.suction_on", "tool.suction_off", "tool.has_part",
    "markers.detect_markers", "markers.marker_pose", "markers.object_pose", "markers.object_found",
    "markers.calibrate_camera", "freedrive.start", "freedrive.stop", "freedrive.record_waypoint",
    "timing.wait_until",
}  # fmt: skip


def test_ops_lists_every_robot_operation_with_reasons_when_no_cell() -> None:
    code, out, _ = run_cli("ops", "--cell", "none", "--json")
    assert code == 0
    ops = {entry["id"]: entry for entry in json.loads(out)}
    assert set(ops) >= EXPECTED_OPS
    move = ops["motion.move_to"]
    assert not move["available"] and "arm" in move["reason"]
    assert {p["name"] for p in move["params"]} >= {"target", "mode", "speed"}
    assert ops["timing.wait_until"]["available"]
    assert "timing.wait" not in ops  # the engine's Wait node waits a time


def test_validate_on_no_cell_hints_at_the_simulated_cell() -> None:
    code, out, _ = run_cli("validate", "--cell", "none", str(EXAMPLES / "cup_to_bin.costar.json"))
    assert code == 2
    assert "the none cell has no arm" in out
    assert "leave out --cell none" in out


def test_ops_into_a_closed_pipe_ends_quietly() -> None:
    proc = subprocess.run(
        f"{sys.executable} -m capabilities.cli ops --cell none | head -n 1",
        shell=True, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.stdout.count("\n") == 1
    assert "Traceback" not in proc.stderr


def test_a_failed_run_names_the_leaf_that_made_it_fail_and_why(tmp_path: Path) -> None:
    text = Binding.fixed("no cup in view", ParamType.TEXT)
    look = NodeSpec(
        NodeKind.OPERATION, "look for the cup", op="debug.fail", params={"message": text}
    )
    choose = NodeSpec(NodeKind.SELECTOR, children=[look])
    tree = NodeSpec(NodeKind.SEQUENCE, children=[choose])
    code, out, _ = run_cli("run", "--cell", "none", "--rate", "200", _save(tmp_path, tree))
    last = out.strip().splitlines()[-1]
    assert code == 1 and "FAILURE" in last
    assert (
        "look for the cup failed: no cup in view" in last and "selector failed" not in out.lower()
    )
