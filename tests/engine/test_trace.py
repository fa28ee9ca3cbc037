"""Traces: the recorder's JSON lines, reading them back, errors with file:line, timelines."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from bt_fakes import logic, op, plan

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.errors import EngineError
from engine.events import (
    BlackboardWritten,
    Event,
    LogMessage,
    RunFinished,
    RunStarted,
    StatusChanged,
)
from engine.executor import Executor
from engine.spec import NodeKind
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS
from engine.trace import Trace, TraceError, TraceRecorder, format_timeline, read_trace
from engine.types import Pose

HEADER = '{"format":"costar-trace","format_version":1}'


def test_a_recorded_run_reads_back(tmp_path: Path, registry: CapabilityRegistry) -> None:
    spec = plan(
        logic(
            NodeKind.SEQUENCE,
            op("debug.query", "where", value=Pose((0.1, 0.2, 0.3)), result="$CUP_POSE"),
            op("debug.running", "move", ticks=1),
            name="transfer",
        ),
        name="cup",
    )
    path = tmp_path / "run.trace.jsonl"
    recorder = TraceRecorder(path, spec)
    executor = Executor(
        build_tree(spec, registry), rate_hz=1000.0, listeners=[recorder], plan_name="cup"
    )
    executor.start()
    assert executor.wait(5.0) is not None
    trace = read_trace(path)
    assert trace.header["plan"] == "cup"
    where, move = spec.tree.children if spec.tree else []
    assert trace.header["nodes"][1] == {
        "id": where.id,
        "label": "where",
        "kind": "debug.query",
        "path": "transfer/where[0]",
    }
    assert trace.labels()[move.id] == "move"
    assert trace.statuses(move.id) == ["RUNNING", "SUCCESS"]
    assert trace.final_status is SUCCESS
    (write,) = [e for e in trace.events if e["event"] == "write"]
    assert write["key"] == "CUP_POSE" and write["node"] == where.id
    assert write["value"]["position"] == [0.1, 0.2, 0.3]
    assert trace.events[0]["event"] == "started" and trace.events[-1]["event"] == "finished"
    lines = path.read_text(encoding="utf-8").splitlines()
    assert all(json.loads(line) for line in lines)  # one JSON object per line


def test_a_trace_names_the_root_causes_of_a_failed_run(
    tmp_path: Path, registry: CapabilityRegistry
) -> None:
    pick = op(
        "debug.fail", "grasp CUP", message="nothing between the fingers", error="grasp_failed"
    )
    ask = op("debug.fail", "ask for help", message="no one answered")
    retry = logic(NodeKind.RETRY, pick, name="pick 4 times", count=4)
    spec = plan(logic(NodeKind.SELECTOR, retry, ask, name="pick or ask"), name="pick")
    path = tmp_path / "run.trace.jsonl"
    executor = Executor(
        build_tree(spec, registry), rate_hz=1000.0, listeners=[TraceRecorder(path, spec)]
    )
    executor.start()
    assert executor.wait(5.0) is not None
    trace = read_trace(path)
    failures, finished = trace.events[-2:]
    assert finished["event"] == "finished" and failures["event"] == "failures"
    assert failures["cause"]["node"] == pick.id and failures["cause"]["times"] == 4
    assert failures["cause"]["error"] == "grasp_failed"
    lines = list(format_timeline(trace))[-3:-1]
    assert [re.split(r" tick +\d+  ", line, maxsplit=1)[1] for line in lines] == [
        "the run failed: grasp CUP failed 4 times (grasp_failed): nothing between the fingers; "
        "passed up by Retry 'pick 4 times', Selector 'pick or ask'",
        "on the way: ask for help failed: no one answered; passed up by Selector 'pick or ask'",
    ]


def test_the_recorder_closes_at_the_end_of_the_run(tmp_path: Path) -> None:
    path = tmp_path / "t.trace.jsonl"
    recorder = TraceRecorder(path)
    recorder(RunFinished(3, FAILURE, "stopped", "", 1.0))
    recorder(LogMessage(4, "n", "after the end", 2.0))  # ignored: the file is closed
    recorder.close()  # idempotent
    trace = read_trace(path)
    assert "nodes" not in trace.header
    assert trace.events == [
        {
            "event": "finished",
            "tick": 3,
            "status": "FAILURE",
            "reason": "stopped",
            "message": "",
            "time": 1.0,
        }
    ]
    assert trace.final_status is FAILURE


def test_each_event_is_on_disk_as_it_is_written_and_a_hold_reads_back(tmp_path: Path) -> None:
    from engine.events import RunHeld

    path = tmp_path / "t.trace.jsonl"
    recorder = TraceRecorder(path)
    recorder(RunHeld(2, "protective stop", 1.0))
    recorder(RunHeld(5, "", 2.0))
    # Not closed: what a killed run leaves behind is already in the file.
    trace = read_trace(path)
    assert [e["reason"] for e in trace.events] == ["protective stop", ""]
    lines = list(format_timeline(trace))
    assert "run held: protective stop" in lines[0] and "run resumed" in lines[1]
    recorder.close()


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.trace.jsonl"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "where", "what"),
    [
        (HEADER + "\n\n{not json\n", ":3:", "expected valid JSON"),
        (HEADER + '\n{"event":"log","tick":NaN}\n', ":2:", "$.tick: expected a finite number"),
        (HEADER + "\n[1, 2]\n", ":2:", "expected a JSON object"),
        (HEADER + '\n\n{"event":"log"}\n{"tick":1}\n', ":4:", "expected an 'event' field"),
        ('{"format":"something else"}\n', ":1:", "expected a header with format 'costar-trace'"),
        ("\n\n" + HEADER.replace(":1}", ":7}") + "\n", ":3:", "format_version 7 is not supported"),
        ("", ":1:", "expected a header"),
    ],
)
def test_bad_trace_files_name_file_and_line(
    tmp_path: Path, text: str, where: str, what: str
) -> None:
    path = write(tmp_path, text)
    with pytest.raises(TraceError) as info:
        read_trace(path)
    message = str(info.value)
    assert message.startswith(f"{path}{where}"), message
    assert what in message
    assert isinstance(info.value, EngineError)


def test_a_missing_trace_file(tmp_path: Path) -> None:
    with pytest.raises(TraceError, match="cannot read"):
        read_trace(tmp_path / "nope.trace.jsonl")


def test_format_timeline_gives_readable_lines(tmp_path: Path) -> None:
    path = tmp_path / "t.trace.jsonl"
    recorder = TraceRecorder(path)
    events: list[Event] = [
        RunStarted(10.0, "cup"),
        StatusChanged(1, "n1", IDLE, RUNNING, "", 10.0),
        BlackboardWritten(1, "COUNT", 3, "n1", 10.25),
        LogMessage(2, "n1", "moving", 10.5),
        StatusChanged(2, "n1", RUNNING, FAILURE, "joint limit", 10.5),
        RunFinished(2, FAILURE, "finished", "n1 failed", 11.0),
    ]
    for event in events:
        recorder(event)
    trace = read_trace(path)
    trace = Trace({**trace.header, "nodes": [{"id": "n1", "label": "move"}]}, trace.events)
    assert list(format_timeline(trace)) == [
        "    0.000s run of cup started",
        "    0.000s tick     1  move: IDLE -> RUNNING",
        "    0.250s tick     1  COUNT = 3",
        "    0.500s tick     2  move: moving",
        "    0.500s tick     2  move: RUNNING -> FAILURE  (joint limit)",
        "    1.000s tick     2  run finished: FAILURE (n1 failed)",
    ]
