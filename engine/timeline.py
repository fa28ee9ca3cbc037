"""A run record as a timeline: what the tree, the blackboard and the robot were at any moment.

A :class:`Timeline` reads a record (``engine.trace``) once and answers questions about a
moment ``t`` (seconds since the run started) without going through the record again:

- the status of every node: the full status map is kept every :data:`CHECKPOINT_EVERY`
  transitions; a query copies the checkpoint before ``t`` and replays at most that many
  transitions after it (a record of 100,000 transitions answers in well under a millisecond);
- the nodes running, outermost first (the plan's order);
- the blackboard's values: each name's writes in time order, found by bisection;
- the robot's joints: the last sample (10 Hz) at or before ``t``;
- the cameras' pictures: each camera's last thumbnail (a JPEG, about one a second) at or
  before ``t``;
- per-node figures (ticks, starts, successes, failures, time RUNNING), counted at load;
- the failure moments: one per tick in which a node failed, naming the first node that did
  (the leaf, as the engine reports the failing leaf before the nodes that pass it up).
"""

from __future__ import annotations

import base64
import binascii
import json
import os
from bisect import bisect_right
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.blackboard import BlackboardEntry
from engine.build import ROOT_ID
from engine.plan_format import PlanFileError
from engine.plan_reader import loads_plan
from engine.spec import PlanSpec
from engine.status import Status
from engine.trace import Trace, read_trace
from engine.types import ParamType, ValueShapeError, decode_value

__all__ = [
    "CHECKPOINT_EVERY",
    "FailureMark",
    "NodeFigures",
    "Timeline",
    "changed_statuses",
]

CHECKPOINT_EVERY = 256  # transitions between two full status maps
_STATUSES = tuple(Status)
_INDEX = {status: index for index, status in enumerate(_STATUSES)}
_IDLE, _RUNNING = _INDEX[Status.IDLE], _INDEX[Status.RUNNING]
_SUCCESS, _FAILURE = _INDEX[Status.SUCCESS], _INDEX[Status.FAILURE]
# Values of these shapes are read back as their type (a record keeps values untyped).
_SHAPED = (ParamType.POSE, ParamType.WAYPOINT, ParamType.REGION)


@dataclass(frozen=True)
class FailureMark:
    """A moment a node failed: ``time`` (s since the start), ``tick``, the first node that
    failed in that tick, and its message and error type.
    """

    time: float
    tick: int
    node_id: str
    index: int  # the failure's transition (0: the record's first)
    message: str = ""
    error: str = ""


@dataclass
class NodeFigures:
    """What a node did over the whole run.

    Attributes:
        ticks: ticks it was ticked in (from each start to its result, both counted).
        starts: times it was started (went from IDLE or a result to RUNNING or a result).
        successes: times it ended with SUCCESS.
        failures: times it ended with FAILURE.
        running_s: seconds it was RUNNING (up to the end of the record if it still was).
    """

    ticks: int = 0
    starts: int = 0
    successes: int = 0
    failures: int = 0
    running_s: float = 0.0


@dataclass
class _Counting:
    """A node's figures while the record is read: where its current activation began."""

    figures: NodeFigures = field(default_factory=NodeFigures)
    started_tick: int | None = None
    running_since: float | None = None


def _decoded(value: Any) -> Any:
    """A recorded value as the run had it: poses, waypoints and regions as their types."""
    if isinstance(value, dict):
        for ptype in _SHAPED:
            try:
                return decode_value(ptype, value)
            except ValueShapeError:
                continue
    return value


class Timeline:
    """A run record, indexed for questions about any moment (see the module doc).

    Args:
        trace: the record, read by :func:`engine.trace.read_trace`.
        name: what the record is called (its file name).
    """

    def __init__(self, trace: Trace, name: str = "") -> None:
        self.name = name
        self.header = trace.header
        nodes = trace.header.get("nodes", [])
        self.labels: dict[str, str] = {n["id"]: n.get("label", n["id"]) for n in nodes}
        # The run's own root (its run policy) above the plan's tree: outermost, first.
        self.labels.setdefault(ROOT_ID, f"the run of {trace.header.get('plan') or 'the plan'}")
        self.node_ids: list[str] = [ROOT_ID, *(n["id"] for n in nodes if n["id"] != ROOT_ID)]
        self._slot: dict[str, int] = {node_id: i for i, node_id in enumerate(self.node_ids)}
        self.start = self._start_time(trace)
        self.times: list[float] = []  # the status transitions, in order
        self._nodes: list[int] = []
        self._news: list[int] = []
        self._checkpoints: list[list[int]] = []  # the status map before transitions k*N
        self._writes: dict[str, tuple[list[float], list[BlackboardEntry]]] = {}
        self._joint_times: list[float] = []
        self._joints: list[tuple[float, ...]] = []
        self._thumbnails: dict[str, tuple[list[float], list[str]]] = {}  # camera -> base64s
        self.failures: list[FailureMark] = []
        self.duration = 0.0
        self._counting: dict[str, _Counting] = {}
        self._read(trace)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Timeline:
        """Read a record file; raises TraceError naming the file and line of what is wrong."""
        return cls(read_trace(path), Path(path).name)

    # ------------------------------------------------------------------ reading

    @staticmethod
    def _start_time(trace: Trace) -> float:
        for event in trace.events:
            if "time" in event:
                return float(event["time"])
        return 0.0

    def _read(self, trace: Trace) -> None:
        state = [_IDLE] * len(self.node_ids)
        last_failed_tick: int | None = None
        for event in trace.events:
            kind = event["event"]
            at = float(event.get("time", self.start)) - self.start
            self.duration = max(self.duration, at)
            if kind == "status":
                self._transition(state, event, at)
                if event["new"] == Status.FAILURE.value and event.get("tick") != last_failed_tick:
                    last_failed_tick = event.get("tick")
                    self.failures.append(
                        FailureMark(
                            at,
                            int(event.get("tick", 0)),
                            event["node"],
                            len(self.times) - 1,
                            str(event.get("message", "")),
                            str(event.get("error", "")),
                        )
                    )
            elif kind == "write":
                entry = BlackboardEntry(
                    event["key"],
                    _decoded(event.get("value")),
                    None,
                    str(event.get("node", "")),
                    int(event.get("tick", 0)),
                    at,
                )
                times, entries = self._writes.setdefault(event["key"], ([], []))
                times.append(at)
                entries.append(entry)
            elif kind == "joints" and event.get("q"):
                self._joint_times.append(at)
                self._joints.append(tuple(float(a) for a in event["q"]))
            elif kind == "thumbnail" and isinstance(event.get("jpeg"), str):
                times, pictures = self._thumbnails.setdefault(str(event.get("camera")), ([], []))
                times.append(at)
                pictures.append(event["jpeg"])
        for counting in self._counting.values():  # still running when the record ends
            if counting.running_since is not None:
                counting.figures.running_s += self.duration - counting.running_since

    def _transition(self, state: list[int], event: dict[str, Any], at: float) -> None:
        node_id = event["node"]
        slot = self._slot.get(node_id)
        if slot is None:  # a node the header does not name (the run's own root, an instance's)
            slot = self._slot[node_id] = len(self.node_ids)
            self.node_ids.append(node_id)
            state.append(_IDLE)
            for checkpoint in self._checkpoints:
                checkpoint.append(_IDLE)
        if len(self.times) % CHECKPOINT_EVERY == 0:
            self._checkpoints.append(list(state))
        new = _INDEX[Status(event["new"])]
        self.times.append(at)
        self._nodes.append(slot)
        self._news.append(new)
        self._count(node_id, state[slot], new, int(event.get("tick", 0)), at)
        state[slot] = new

    def _count(self, node_id: str, old: int, new: int, tick: int, at: float) -> None:
        counting = self._counting.setdefault(node_id, _Counting())
        figures = counting.figures
        if old != _RUNNING and new != _IDLE:
            figures.starts += 1
            counting.started_tick = tick
        if counting.running_since is not None and new != _RUNNING:
            figures.running_s += at - counting.running_since
            counting.running_since = None
        if new == _RUNNING and counting.running_since is None:
            counting.running_since = at
        ended = new in (_SUCCESS, _FAILURE) or (new == _IDLE and old == _RUNNING)
        if ended and counting.started_tick is not None:
            figures.ticks += tick - counting.started_tick + 1
            counting.started_tick = None
        figures.successes += new == _SUCCESS
        figures.failures += new == _FAILURE

    # ------------------------------------------------------------------ questions

    @property
    def transitions(self) -> int:
        return len(self.times)

    def plan(self) -> PlanSpec | None:
        """The plan as it ran (None: a record without it, or one this program cannot read)."""
        document = self.header.get("plan_document")
        if not isinstance(document, dict):
            return None
        try:
            return loads_plan(json.dumps(document), self.name or "run record")
        except PlanFileError:
            return None

    def index_at(self, t: float) -> int:
        """How many status transitions happened at or before ``t``."""
        return bisect_right(self.times, t)

    def statuses_at(self, t: float) -> dict[str, Status]:
        """Every node's status at ``t`` (IDLE for those not started yet)."""
        return self.statuses_after(self.index_at(t))

    def statuses_after(self, index: int) -> dict[str, Status]:
        """Every node's status after the record's first ``index`` transitions."""
        state = self._state_at(index)
        return {node_id: _STATUSES[state[slot]] for node_id, slot in self._slot.items()}

    def _state_at(self, index: int) -> list[int]:
        if not self._checkpoints:
            return [_IDLE] * len(self.node_ids)
        base = min(index // CHECKPOINT_EVERY, len(self._checkpoints) - 1)
        state = list(self._checkpoints[base])
        nodes, news = self._nodes, self._news
        for i in range(base * CHECKPOINT_EVERY, index):
            state[nodes[i]] = news[i]
        return state

    def running_at(self, t: float) -> list[str]:
        """The nodes RUNNING at ``t``, in the plan's order (outermost first)."""
        return self.running_after(self.index_at(t))

    def running_after(self, index: int) -> list[str]:
        """The nodes RUNNING after the record's first ``index`` transitions."""
        state = self._state_at(index)
        return [node_id for node_id, slot in self._slot.items() if state[slot] == _RUNNING]

    def values_at(self, t: float) -> list[BlackboardEntry]:
        """The blackboard at ``t``: each name's last write at or before it."""
        entries = []
        for times, writes in self._writes.values():
            index = bisect_right(times, t)
            if index:
                entries.append(writes[index - 1])
        return entries

    def joints_at(self, t: float) -> tuple[float, ...] | None:
        """The robot's joints (rad) at ``t``: the last sample before it (None: no sample yet)."""
        index = bisect_right(self._joint_times, t)
        return self._joints[index - 1] if index else None

    @property
    def has_joints(self) -> bool:
        return bool(self._joints)

    @property
    def cameras(self) -> list[str]:
        """The cameras the record has pictures of, by name."""
        return sorted(self._thumbnails)

    def pictures_at(self, t: float) -> dict[str, bytes]:
        """Each camera's picture at ``t`` (JPEG bytes): its last thumbnail at or before ``t``
        (a camera with none yet, or a picture that is not base64, is left out).
        """
        pictures = {}
        for camera, (times, encoded) in self._thumbnails.items():
            index = bisect_right(times, t)
            if index:
                try:
                    pictures[camera] = base64.b64decode(encoded[index - 1], validate=True)
                except (binascii.Error, ValueError):
                    continue
        return pictures

    def picture_time(self, camera: str, t: float) -> float | None:
        """When the picture of ``camera`` shown at ``t`` was taken (None: none yet)."""
        times = self._thumbnails.get(camera, ([], []))[0]
        index = bisect_right(times, t)
        return times[index - 1] if index else None

    def figures(self, node_id: str) -> NodeFigures:
        """What the node did over the run (all zero: it never ran)."""
        counting = self._counting.get(node_id)
        return counting.figures if counting is not None else NodeFigures()

    def label(self, node_id: str) -> str:
        return self.labels.get(node_id, node_id)

    def failure_near(self, t: float, tolerance: float) -> FailureMark | None:
        """The failure mark nearest ``t`` within ``tolerance`` seconds (None: none)."""
        times = [mark.time for mark in self.failures]
        index = bisect_right(times, t)
        near = [
            m for m in self.failures[max(0, index - 1) : index + 1] if abs(m.time - t) <= tolerance
        ]
        return min(near, key=lambda m: abs(m.time - t)) if near else None


def changed_statuses(before: dict[str, Status], after: dict[str, Status]) -> dict[str, Status]:
    """The statuses of ``after`` that differ from ``before`` (what a view repaints)."""
    return {node_id: status for node_id, status in after.items() if before.get(node_id) != status}
