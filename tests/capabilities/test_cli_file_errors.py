"""Regressions found by an outside test of the engine (issue 8, item 7): deep values, file
names as given, problem lines that name the file.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

from capabilities.cli import main
from engine.events import BlackboardWritten
from engine.trace import TraceRecorder, read_trace
from engine.types import MAX_VALUE_DEPTH, encode_value


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def nested(depth: int) -> Any:
    value: Any = 1
    for _ in range(depth):
        value = [value]
    return value


def set_param_plan(value: Any) -> dict[str, Any]:
    return {
        "format": "costar-plan",
        "format_version": 1,
        "name": "deep",
        "tree": {
            "id": "set",
            "kind": "operation",
            "op": "debug.set_param",
            "params": {"value": {"type": "Any", "value": value}, "name": {"ref": "DEEP"}},
        },
    }


def write(folder: Path, doc: Any, name: str = "deep.costar.json") -> str:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(json.dumps(doc), encoding="utf-8")
    return str(folder / name)


def test_a_value_nested_900_deep_is_refused_with_its_path_not_a_traceback(tmp_path: Path) -> None:
    plan = write(tmp_path / "plans", set_param_plan(nested(900)))
    trace = tmp_path / "run.trace.jsonl"
    code, _, err = run_cli("run", "--verbose", "--cell", "none", "--trace", str(trace), plan)
    assert code == 2, err
    assert err.startswith(f"error: {plan}: $.tree.params.value.value[0][0]")
    assert "expected nesting at most" in err and "Traceback" not in err


def test_a_value_too_deep_for_a_parameter_names_its_path(tmp_path: Path) -> None:
    plan = write(tmp_path, set_param_plan(nested(MAX_VALUE_DEPTH + 5)))
    code, _, err = run_cli("validate", "--cell", "none", plan)
    assert code == 2
    assert f"{plan}: $.tree.params.value.value[0]" in err
    assert f"a value nested at most {MAX_VALUE_DEPTH} levels deep" in err


def test_a_deep_value_within_the_limit_runs_verbose_and_is_traced(tmp_path: Path) -> None:
    plan = write(tmp_path, set_param_plan(nested(MAX_VALUE_DEPTH - 2)))
    trace = tmp_path / "run.trace.jsonl"
    code, out, err = run_cli("run", "--verbose", "--cell", "none", "--trace", str(trace), plan)
    assert code == 0, err
    assert "DEEP = [[[" in out
    writes = [e for e in read_trace(trace).events if e["event"] == "write"]
    assert [w["key"] for w in writes] == ["DEEP"] and writes[0]["value"] == nested(
        MAX_VALUE_DEPTH - 2
    )


def test_a_value_nested_deeper_at_run_time_is_still_traced(tmp_path: Path) -> None:
    """An operation may write any Python value; the trace keeps the event, cut short."""
    path = tmp_path / "t.trace.jsonl"
    recorder = TraceRecorder(path)
    recorder(BlackboardWritten(3, "DEEP", nested(5000), "node", 1.0))
    recorder.close()
    (write_event,) = read_trace(path).events
    assert write_event["key"] == "DEEP" and write_event["tick"] == 3
    assert json.dumps(write_event["value"]).endswith(
        f'"<nested deeper than {MAX_VALUE_DEPTH} levels>"' + "]" * MAX_VALUE_DEPTH
    )
    assert encode_value(nested(5000)) == write_event["value"]


def test_file_errors_name_the_path_as_given(tmp_path: Path) -> None:
    doc = set_param_plan(1)
    doc["tree"]["params"]["value"]["value"] = float("nan")
    plan = tmp_path / "sub" / "nan.costar.json"
    plan.parent.mkdir()
    plan.write_text(json.dumps(doc), encoding="utf-8")  # json.dumps writes NaN
    code, _, err = run_cli("validate", "--cell", "none", str(plan))
    assert code == 2
    assert err.startswith(f"error: {plan}: $.tree.params.value.value: expected a finite number")
    big = str(plan).replace("nan.", "big.")
    Path(big).write_text(json.dumps(doc).replace("NaN", "9" * 5000), encoding="utf-8")
    code, _, err = run_cli("validate", "--cell", "none", big)
    assert err.startswith(f"error: {big}: $.tree.params.value.value: expected a shorter number")


def test_each_problem_line_names_the_file_and_the_count_reads_right(tmp_path: Path) -> None:
    doc = set_param_plan(1)
    doc["tree"]["op"] = "debug.no_such_thing"
    plan = write(tmp_path, doc, "one.costar.json")
    code, out, _ = run_cli("validate", "--cell", "none", plan)
    assert code == 2
    problems = [line for line in out.splitlines() if ": error: " in line]
    assert problems and all(line.startswith(f"{plan}: error: ") for line in problems)
    assert out.splitlines()[-1] == f"{plan}: invalid (1 error)"
    doc["tree"] = {"id": "s", "kind": "sequence", "children": [
        {**doc["tree"], "id": "a"}, {**doc["tree"], "id": "b"},
    ]}  # fmt: skip
    plan = write(tmp_path, doc, "two.costar.json")
    code, out, _ = run_cli("validate", "--cell", "none", plan)
    assert f"{plan}: invalid (2 errors)" in out
