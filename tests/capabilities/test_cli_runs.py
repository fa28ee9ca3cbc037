"""Every `costar run` keeps a record in the runs folder; `costar runs list/show` read them."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from capabilities.cli import main
from capabilities.collaboration.console import OperatorConsole
from capabilities.run_sampler import OperatorActions
from engine.events import RunFinished, RunStarted
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.trace import TraceRecorder, format_timeline, read_trace
from engine.types import ParamType

FIGURE3 = (
    Path(__file__).resolve().parents[2] / "resources" / "examples" / "figure3_debug.costar.json"
)


def _cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def test_a_run_keeps_a_record_that_runs_list_and_show_read(tmp_path: Path) -> None:
    runs = tmp_path / "runs"
    code, out, _ = _cli("run", "--cell", "none", str(FIGURE3), "--rate", "200", "--runs", str(runs))
    assert code == 0
    records = list(runs.iterdir())
    assert len(records) == 1 and f"run record: {records[0]}" in out
    code, listing, _ = _cli("runs", "list", "--runs", str(runs))
    assert code == 0 and "1 run records" in listing
    assert "Figure 3" in listing and "SUCCESS after" in listing
    code, shown, _ = _cli("runs", "show", "last", "--runs", str(runs))
    assert code == 0 and shown.startswith("trace of Figure 3")
    assert shown.splitlines()[-1].endswith("run finished: SUCCESS")


def test_the_variable_names_the_folder_and_no_record_keeps_none(
    tmp_path: Path, monkeypatch
) -> None:
    monkeypatch.setenv("COSTAR_RUNS", str(tmp_path / "env"))
    assert _cli("run", "--cell", "none", str(FIGURE3), "--rate", "200")[0] == 0
    assert len(list((tmp_path / "env").iterdir())) == 1
    assert _cli("run", "--cell", "none", str(FIGURE3), "--rate", "200", "--no-record")[0] == 0
    assert len(list((tmp_path / "env").iterdir())) == 1
    code, _, err = _cli("runs", "show", "nothing-like-it")
    assert code == 2 and "no run record" in err


def test_a_killed_run_leaves_a_readable_record(tmp_path: Path) -> None:
    tree = NodeSpec(NodeKind.OPERATION, "spin", op="debug.running",
                    params={"ticks": Binding.fixed(100_000, ParamType.NUMBER)})  # fmt: skip
    plan = tmp_path / "spin.costar.json"
    save_plan(PlanSpec(tree, "spin"), plan)
    runs = tmp_path / "runs"
    env = dict(os.environ, COSTAR_RUNS=str(runs))
    command = [sys.executable, "-m", "capabilities.cli", "run", "--cell", "none", str(plan),
               "--verbose", "--rate", "50"]  # fmt: skip
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout is not None
        assert "RUNNING" in proc.stdout.readline()  # the run has started
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    code, listing, _ = _cli("runs", "list", "--runs", str(runs))
    assert code == 0 and "spin: cut short (no end recorded)" in listing
    code, shown, err = _cli("runs", "show", "last", "--runs", str(runs))
    assert code == 0, err
    assert "spin" in shown and "RUNNING" in shown


def test_only_a_run_on_the_simulated_cell_replays(tmp_path: Path) -> None:
    runs = tmp_path / "runs"
    assert _cli("run", "--cell", "none", str(FIGURE3), "--rate", "200", "--runs", str(runs))[0] == 0
    code, _, err = _cli("runs", "replay", "last", "--runs", str(runs))
    assert code == 2 and "only a run on the simulated cell replays, not on 'none'" in err


def test_runs_show_prints_the_operators_questions_and_answers_in_order(tmp_path: Path) -> None:
    asks = [
        NodeSpec(NodeKind.OPERATION, name=f"ask {i}", op="collaboration.confirm",
                 params={"prompt": Binding.fixed(f"Question {i}?", ParamType.TEXT)})
        for i in range(2)
    ]  # fmt: skip
    plan = tmp_path / "confirm.costar.json"
    save_plan(PlanSpec(NodeSpec(NodeKind.SEQUENCE, "steps", children=asks), "confirm"), plan)
    runs = tmp_path / "runs"
    out, err = io.StringIO(), io.StringIO()
    argv = ["run", "--cell", "none", str(plan), "--confirm", "ask", "--runs", str(runs)]
    assert main(argv, out, err, io.StringIO("y\nn\n")) == 1
    code, shown, _ = _cli("runs", "show", "last", "--runs", str(runs))
    assert code == 0
    said = [
        line.split("s ", 1)[1].strip()
        for line in shown.splitlines()
        if "Question" in line and "tick" not in line
    ]
    assert said == [
        "operator asked: Question 0? (asked by ask 0)",
        "operator answered yes (by the terminal): Question 0?",
        "operator asked: Question 1? (asked by ask 1)",
        "operator answered no (by the terminal): Question 1?",
    ]
    lines = shown.splitlines()
    answered = next(i for i, line in enumerate(lines) if "answered no" in line)
    assert "-> FAILURE  (failed: declined)" in "".join(lines[answered:])  # after the answer


def test_presses_and_withdrawn_questions_are_recorded_until_the_run_ends(tmp_path: Path) -> None:
    path = tmp_path / "run.trace.jsonl"
    recorder, console = TraceRecorder(path), OperatorConsole()
    actions = OperatorActions(console, recorder)
    recorder(RunStarted(time.monotonic(), "p"))
    prompt = console.ask("Is the bin empty?", "check bin")
    console.press("continue", "digital input")
    console.cancel(prompt.id, "timed out")
    finished = RunFinished(3, Status.SUCCESS, "finished", "", time.monotonic())
    actions(finished)
    recorder(finished)
    console.press("continue", "the Instructor")  # after the run: not in its record
    trace = read_trace(path)
    operator = [e for e in trace.events if e["event"] == "operator"]
    assert [e["action"] for e in operator] == ["asked", "pressed", "withdrawn"]
    assert operator[1]["by"] == "digital input" and operator[2]["reason"] == "timed out"
    shown = list(format_timeline(trace))
    assert shown[-3].endswith("operator pressed continue (by digital input)")
    assert shown[-2].endswith("question withdrawn (timed out): Is the bin empty?")
