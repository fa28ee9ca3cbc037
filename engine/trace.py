"""Traces: every event of a run as JSON lines (``*.trace.jsonl``), for replay and analysis.

The first line is a header with the plan's nodes (id, label, kind, path), so a trace can be
read without the plan; each further line is one event. When the run had failures, a
``failures`` record before the last one names their root causes (``engine.run_report``):
the one that failed the run (``cause``) and those on the way. A cell adds records of its
own between the events (:meth:`TraceRecorder.note`, ``capabilities.run_sampler``): the
robot's ``joints``, a camera's ``thumbnail`` (a JPEG in base64), the ``operator`` console's
questions, answers and presses. A reader skips the kinds it does not know.
"""

from __future__ import annotations

import json
import os
import threading
import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from engine.errors import EngineError
from engine.events import (
    BlackboardWritten,
    Event,
    LogMessage,
    RunFinished,
    RunHeld,
    RunPaused,
    StatusChanged,
)
from engine.json_reader import JsonFileError, errors_as, parse_json
from engine.plan_writer import dump_plan
from engine.run_report import FailureLog, RootCause
from engine.spec import PlanSpec
from engine.status import Status
from engine.types import encode_value

__all__ = [
    "TraceRecorder",
    "Trace",
    "TraceError",
    "read_trace",
    "format_timeline",
    "in_time_order",
]

TRACE_FORMAT = "costar-trace"
TRACE_VERSION = 1


class TraceError(EngineError):
    """A trace file cannot be read; the message names the file and line."""


def _event_record(event: Event) -> dict[str, Any]:
    if isinstance(event, StatusChanged):
        fields = {"node": event.node_id, "old": event.old.value, "new": event.new.value}
        if event.message:
            fields["message"] = event.message
        if event.error:  # absent in traces written before error types: read as untyped
            fields["error"] = event.error
        return _ticked("status", event, **fields)
    if isinstance(event, BlackboardWritten):
        return _ticked(
            "write", event, key=event.key, value=encode_value(event.value), node=event.node_id
        )
    if isinstance(event, LogMessage):
        return _ticked("log", event, node=event.node_id, message=event.message)
    if isinstance(event, RunFinished):
        return _ticked(
            "finished",
            event,
            status=event.status.value,
            reason=event.reason,
            message=event.message,
        )
    if isinstance(event, RunHeld):
        return _ticked("held", event, reason=event.reason)
    if isinstance(event, RunPaused):
        return _ticked("paused", event, node=event.node_id, where=event.where, why=event.why)
    return {"event": "started", "plan": event.plan, "time": event.time}


def _ticked(name: str, event: Any, **fields: Any) -> dict[str, Any]:
    """The record of an event of a tick: its name and tick, its own fields, then its time."""
    return {"event": name, "tick": event.tick, **fields, "time": event.time}


class TraceRecorder:
    """A listener that writes a run's events to a JSON-lines file.

    It runs on the executor's dispatcher thread, so file writes never delay a tick. Each
    event is flushed as it is written: a run that is killed leaves its trace up to that moment.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        plan: PlanSpec | None = None,
        run: dict[str, Any] | None = None,
    ) -> None:
        """``run``: how the run was started (cell, scene, seed, rate), for a replay."""
        self.path = Path(path)
        self._lock = threading.Lock()
        self._file: TextIO | None = self.path.open("w", encoding="utf-8")
        self._failures = FailureLog(plan) if plan is not None else None
        header: dict[str, Any] = {
            "format": TRACE_FORMAT,
            "format_version": TRACE_VERSION,
            "started_us": time.time_ns() // 1000,  # wall clock: events carry monotonic times
        }
        if plan is not None:
            header["plan"] = plan.name
            # The plan as it ran, so that the record can be read (and exported) without it.
            header["plan_document"] = json.loads(dump_plan(plan))
            header["nodes"] = [
                {
                    "id": node.id,
                    "label": node.label,
                    "kind": node.op or node.kind.value,
                    "path": path,
                }
                for path, node in plan.walk()
            ]
        if run is not None:
            header["run"] = run
        self._write(header)

    def _write(self, record: dict[str, Any]) -> None:
        try:
            line = json.dumps(record, separators=(",", ":"))
        except (TypeError, ValueError, RecursionError) as exc:  # never drop an event silently
            kept = {k: v for k, v in record.items() if k != "value"}
            line = json.dumps(kept | {"value": f"<not written: {exc}>"}, separators=(",", ":"))
        with self._lock:
            if self._file is not None:
                self._file.write(line + "\n")
                self._file.flush()

    def __call__(self, event: Event) -> None:
        failures = self._failures
        if isinstance(event, RunFinished):
            if failures is not None:
                self._write_failures(failures, event)
            self._write(_event_record(event))
            self.close()
            return
        if failures is not None:
            failures(event)
        self._write(_event_record(event))

    def note(self, record: dict[str, Any]) -> None:
        """Add a record of the cell's own between the run's events (the robot's joints; any
        thread): ``record`` with its ``event`` kind, stamped with the events' clock. Ignored
        once the run's record is closed.
        """
        self._write({**record, "time": time.monotonic()})

    def _write_failures(self, failures: FailureLog, event: RunFinished) -> None:
        cause = failures.failed_run() if event.reason == "finished" else None
        others = [c for c in failures.root_causes() if c != cause]
        if cause is None and not others:
            return
        record: dict[str, Any] = {"event": "failures", "tick": event.tick}
        if cause is not None:
            record["cause"] = cause.as_record()
        record["on_the_way"] = [other.as_record() for other in others]
        self._write(record | {"time": event.time})

    def close(self) -> None:
        with self._lock:
            if self._file is not None:
                self._file.close()
                self._file = None


@dataclass
class Trace:
    """A trace read back: its header and its event records, in order."""

    header: dict[str, Any]
    events: list[dict[str, Any]] = field(default_factory=list)

    def labels(self) -> dict[str, str]:
        return {n["id"]: n["label"] for n in self.header.get("nodes", [])}

    def statuses(self, node_id: str) -> list[str]:
        """The statuses a node went through, in order."""
        return [e["new"] for e in self.events if e["event"] == "status" and e["node"] == node_id]

    @property
    def final_status(self) -> Status | None:
        for event in reversed(self.events):
            if event["event"] == "finished":
                return Status(event["status"])
        return None


def read_trace(path: str | os.PathLike[str]) -> Trace:
    """Load a trace; raises TraceError naming the file and line of anything wrong."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
        lines = text.splitlines()
    except OSError as exc:
        raise TraceError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise TraceError(
            f"{path}: not a trace file: a byte that is not UTF-8 at offset {exc.start}"
        ) from exc
    if lines and not text.endswith("\n"):
        # The run was killed while its last event was written: the record ends before it.
        try:
            parse_json(lines[-1], str(path), "trace")
        except JsonFileError:
            lines.pop()
    records: list[tuple[int, dict[str, Any]]] = []  # (line number in the file, record)
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        with errors_as(TraceError):
            record = parse_json(line, f"{path}:{number}", "trace")
        if not isinstance(record, dict):
            raise TraceError(f"{path}:{number}: expected a JSON object")
        records.append((number, record))
    first, header = records[0] if records else (1, {})
    if header.get("format") != TRACE_FORMAT:
        raise TraceError(f"{path}:{first}: expected a header with format {TRACE_FORMAT!r}")
    version = header.get("format_version")
    if version != TRACE_VERSION:
        raise TraceError(
            f"{path}:{first}: format_version {version!r} is not supported (only {TRACE_VERSION})"
        )
    for number, record in records[1:]:
        if "event" not in record:
            raise TraceError(f"{path}:{number}: expected an 'event' field")
    return Trace(header, [record for _, record in records[1:]])


def _held_words(event: dict[str, Any]) -> str:
    """What a record of a hold or a pause says: the run held, resumed or paused."""
    if event["event"] == "paused":
        return f"paused: {event.get('why', '')}"
    return f"held: {event['reason']}" if event.get("reason") else "resumed"


def _operator_words(event: dict[str, Any]) -> str:
    """What a record of the operator console says: a question, its answer, a press."""
    action, text = event.get("action"), event.get("text", "")
    by = f" (by {event['by']})" if event.get("by") else ""
    if action == "asked":
        source = f" (asked by {event['source']})" if event.get("source") else ""
        return f"operator asked: {text}{source}"
    if action == "answered":
        return f"operator answered {event.get('answer')}{by}: {text}"
    if action == "withdrawn":
        return f"question withdrawn ({event.get('reason') or 'no reason given'}): {text}"
    if action == "pressed":
        return f"operator pressed {event.get('button', '')}{by}"
    return f"operator: {action}"


def _failure_lines(event: dict[str, Any], tick: str) -> Iterable[str]:
    """What a record of the run's failures says: the cause, then those on the way."""
    if isinstance(event.get("cause"), dict):
        yield f"{tick}the run failed: {RootCause.from_record(event['cause']).describe()}"
    for other in event.get("on_the_way", []):
        if isinstance(other, dict):
            yield f"{tick}on the way: {RootCause.from_record(other).describe()}"


def in_time_order(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The records by their times: the cell's own (joints, pictures, the operator's
    actions), written from other threads as they happen, go between the run's events,
    which the dispatcher writes a moment later. A record without a time keeps its place
    after the one before it; records of the same time keep their order.
    """
    keys, last = [], float("-inf")
    for event in events:
        stamp = event.get("time")
        last = float(stamp) if isinstance(stamp, (int, float)) else last
        keys.append(last)
    order = sorted(range(len(events)), key=keys.__getitem__)
    return [events[i] for i in order]


def format_timeline(trace: Trace) -> Iterable[str]:
    """Readable lines in time order: time since start, tick, node, change, message."""
    labels = trace.labels()
    start: float | None = None
    for event in in_time_order(trace.events):
        stamp = float(event.get("time", 0.0))
        start = stamp if start is None else start
        head = f"{stamp - start:9.3f}s"
        kind = event["event"]
        if kind == "status":
            label = labels.get(event["node"], event["node"])
            text = f"{head} tick {event['tick']:>5}  {label}: {event['old']} -> {event['new']}"
            why = ": ".join(str(event[k]) for k in ("error", "message") if event.get(k))
            yield text + (f"  ({why})" if why else "")
        elif kind == "write":
            yield f"{head} tick {event['tick']:>5}  {event['key']} = {json.dumps(event['value'])}"
        elif kind == "log":
            label = labels.get(event["node"], event["node"])
            yield f"{head} tick {event['tick']:>5}  {label}: {event['message']}"
        elif kind == "finished":
            tail = f" ({event['message']})" if event.get("message") else ""
            yield f"{head} tick {event['tick']:>5}  run {event['reason']}: {event['status']}{tail}"
        elif kind in ("held", "paused"):
            yield f"{head} tick {event['tick']:>5}  run {_held_words(event)}"
        elif kind == "failures":
            yield from _failure_lines(event, f"{head} tick {event['tick']:>5}  ")
        elif kind == "operator":
            yield f"{head}             {_operator_words(event)}"
        elif kind == "started":
            yield f"{head} run of {event.get('plan') or 'plan'} started"
