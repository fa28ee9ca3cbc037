"""Fakes shared by the engine tests (imported by them and by conftest.py): a fake clock, scripted leaves, controllable jobs, a
recording listener, and small builders of plan specs.

Everything here is deterministic: time only moves when a test advances the clock, and a
scripted leaf returns exactly the statuses it is given.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from engine.blackboard import Blackboard
from engine.context import TreeContext
from engine.events import Event, StatusChanged
from engine.kinds import setting
from engine.leaves import OperationLeaf
from engine.node import Node
from engine.operations import Job, OperationCall, OperationKind, StartResult
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import SUCCESS, Status
from engine.tree import BehaviorTree, Root, RunPolicy
from engine.types import ParamType, Pose


class FakeClock:
    """A clock that only moves when told to."""

    def __init__(self, start: float = 100.0) -> None:
        self.now = start

    def __call__(self) -> float:
        return self.now

    def advance(self, seconds: float) -> None:
        self.now += seconds


class ScriptedLeaf(Node):
    """A leaf that returns the given statuses, one per evaluation; the last one repeats.

    Attributes:
        updates: how many times it was evaluated (latching shows as no increase).
        halts: how many times it was halted while RUNNING.
        resets: how many times it was reset from a non-IDLE status.
    """

    kind = "scripted"

    def __init__(
        self,
        ctx: TreeContext,
        name: str,
        *statuses: Status,
        condition: bool = False,
    ) -> None:
        super().__init__(ctx, name, name)
        self.script = list(statuses) or [SUCCESS]
        self.is_condition = condition
        self.updates = 0
        self.halts = 0
        self.resets = 0

    def update(self) -> Status:
        index = min(self.updates, len(self.script) - 1)
        self.updates += 1
        return self.script[index]

    def set_script(self, *statuses: Status) -> None:
        """Replace the script; evaluation restarts at its first status."""
        self.script = list(statuses)
        self.updates = 0

    def on_halt(self) -> None:
        self.halts += 1

    def on_reset(self) -> None:
        self.resets += 1


class CountingJob(Job):
    """A Job finished by the test (any thread) that counts its cancel calls."""

    def __init__(self) -> None:
        super().__init__(on_cancel=self._count_cancel)
        self.cancels = 0

    def _count_cancel(self) -> None:
        self.cancels += 1


class JobOperation:
    """An operation whose every start returns a new CountingJob (kept in ``jobs``).

    ``started`` is set from the engine thread when a start happened, so executor tests can
    finish the job from the test thread at the right moment.
    """

    def __init__(self) -> None:
        self.jobs: list[CountingJob] = []
        self.calls: list[dict[str, Any]] = []
        self.started = threading.Event()

    def start(self, call: OperationCall) -> StartResult:
        job = CountingJob()
        self.jobs.append(job)
        self.calls.append(dict(call.args))
        self.started.set()
        return job

    @property
    def job(self) -> CountingJob:
        """The latest job."""
        return self.jobs[-1]


class FuncOperation:
    """An operation that runs a function of the call (for one-off behaviours)."""

    def __init__(self, func: Callable[[OperationCall], StartResult]) -> None:
        self.func = func
        self.starts = 0

    def start(self, call: OperationCall) -> StartResult:
        self.starts += 1
        return self.func(call)


class Recorder:
    """A listener that keeps every event (thread-safe enough: list.append is atomic)."""

    def __init__(self) -> None:
        self.events: list[Event] = []

    def __call__(self, event: Event) -> None:
        self.events.append(event)

    def of(self, kind: type) -> list[Any]:
        return [e for e in self.events if isinstance(e, kind)]

    def statuses(self, node_id: str) -> list[Status]:
        """The statuses a node went through, in order."""
        return [e.new for e in self.of(StatusChanged) if e.node_id == node_id]


class _RecordingContext(TreeContext):
    __slots__ = ("changes", "logs")
    changes: list[tuple[str, Status, Status]]
    logs: list[tuple[str, str]]


def recording_ctx(clock: FakeClock | None = None, board: Blackboard | None = None) -> Any:
    """A context that records status changes (``changes``) and log lines (``logs``)."""
    ctx = _RecordingContext(board, clock or FakeClock())
    ctx.changes = []
    ctx.logs = []
    ctx.status_sink = lambda node, old, new: ctx.changes.append((node.id, old, new))
    ctx.log_sink = lambda node_id, message: ctx.logs.append((node_id, message))
    return ctx


def leaf(
    ctx: TreeContext,
    operation: Any,
    name: str = "op",
    kind: OperationKind = OperationKind.ACTION,
    fixed: Mapping[str, Any] | None = None,
    refs: Mapping[str, str] | None = None,
    outputs: Mapping[str, str] | None = None,
) -> OperationLeaf:
    """An operation leaf around any object with ``start(call)``."""
    return OperationLeaf(ctx, name, name, kind, operation, fixed, refs, outputs)


def rooted(ctx: TreeContext, child: Node, policy: RunPolicy = RunPolicy.ONCE) -> BehaviorTree:
    """A tree of one child under a root with the given run policy."""
    root = Root(ctx, "root", "root", policy)
    root.set_children([child])
    return BehaviorTree(root, ctx)


def with_children(node: Node, children: Iterable[Node]) -> Node:
    node.set_children(list(children))
    return node


def wait_until(predicate: Callable[[], bool], timeout: float = 5.0) -> bool:
    """Poll until ``predicate`` holds (like qtbot.waitUntil); False on timeout.

    The sleep only paces the polling; the outcome is decided by the predicate.
    """
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.001)
    return True


# ---------------------------------------------------------------------- plan specs


def op(op_id: str, label: str = "", **params: Any) -> NodeSpec:
    """An operation node; a str starting with '$' is a reference, else a fixed value."""
    bindings: dict[str, Binding] = {}
    for port, value in params.items():
        if isinstance(value, str) and value.startswith("$"):
            bindings[port] = Binding.reference(value[1:])
        else:
            bindings[port] = Binding.fixed(value, _ptype(value))
    return NodeSpec(NodeKind.OPERATION, name=label, op=op_id, params=bindings)


def _ptype(value: Any) -> ParamType:
    if isinstance(value, bool):
        return ParamType.BOOL
    if isinstance(value, (int, float)):
        return ParamType.NUMBER
    if isinstance(value, str):
        return ParamType.TEXT
    if isinstance(value, Pose):
        return ParamType.POSE
    return ParamType.ANY


def settings(kind: NodeKind, **values: Any) -> dict[str, Binding]:
    """Port bindings of a logic node from plain values (None: unbound; odd values kept as Any)."""
    out: dict[str, Binding] = {}
    for name, value in values.items():
        if value is None:
            continue
        try:
            out[name] = setting(kind, name, value)
        except ValueError:
            out[name] = Binding.fixed(value, ParamType.ANY)
    return out


def logic(kind: NodeKind, *children: NodeSpec, name: str = "", **config: Any) -> NodeSpec:
    """A logic node with children and settings."""
    return NodeSpec(kind, name=name, params=settings(kind, **config), children=list(children))


def plan(tree: NodeSpec, policy: RunPolicy = RunPolicy.ONCE, **kwargs: Any) -> PlanSpec:
    return PlanSpec(tree=tree, name=kwargs.pop("name", "test plan"), run_policy=policy, **kwargs)
