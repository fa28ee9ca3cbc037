"""Leaves: operation leaves (Action, Query, Condition), Wait, and the script leaves.

An operation leaf never blocks a tick: on its first tick it resolves its inputs and calls
the operation's ``start``; if that returns a Job, later ticks poll it, and a reset cancels
it. Anything the operation raises becomes FAILURE of this node with the message.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from engine.blackboard import MISSING
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.node import Node
from engine.operations import (
    Job,
    Operation,
    OperationCall,
    OperationFailed,
    OperationKind,
    PortSpec,
    read_reference,
    typed_input,
)
from engine.script import ScriptEnv, ScriptRunError, parse_script
from engine.status import RUNNING, SUCCESS, Status

__all__ = ["OperationLeaf", "ScriptLeaf", "Wait"]


def _error_text(exc: BaseException) -> str:
    if isinstance(exc, OperationFailed):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


def _error_type(exc: BaseException) -> ErrorType:
    """An OperationFailed names its type; any other exception is unexpected: ``error``."""
    return exc.error if isinstance(exc, OperationFailed) else ErrorType.ERROR


class OperationLeaf(Node):
    """A leaf that runs one capability operation.

    Args:
        ctx: the tree's context.
        node_id: id of the spec node.
        name: label.
        op_kind: action, query or condition (from the manifest).
        operation: the operation's code, one instance for this leaf.
        fixed: input port -> literal value (defaults included).
        refs: input port -> blackboard key read at each start.
        outputs: output port -> blackboard key written.
        ports: the manifest's input ports: fixed values are given to the operation as the
            port's type, and a reference's value is checked against the port's types when
            read (a value of another type fails the node, naming port, name and types).
        capability: the capability the operation belongs to (a cell's stop may spare it).
    """

    kind = "operation"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        op_kind: OperationKind,
        operation: Operation,
        fixed: Mapping[str, Any] | None = None,
        refs: Mapping[str, str] | None = None,
        outputs: Mapping[str, str] | None = None,
        *,
        ports: Sequence[PortSpec] = (),
        capability: str = "",
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.capability = capability
        self.op_kind = op_kind
        self.kind = op_kind.value
        self.is_condition = op_kind is OperationKind.CONDITION
        # Kept as a bool: an enum member lookup (OperationKind.QUERY) costs ~65 ns on
        # Python 3.11, a noticeable share of a leaf's tick.
        self._is_query = op_kind is OperationKind.QUERY
        self.operation = operation
        by_name = {p.name: p for p in ports}
        self._fixed = {
            k: typed_input(by_name[k], v) if k in by_name else v for k, v in (fixed or {}).items()
        }
        self._refs = tuple((port, key, by_name.get(port)) for port, key in (refs or {}).items())
        self._written: set[str] = set()
        self._call = OperationCall(
            node_id, self.name, outputs or {}, self._write, ctx.log, self._wake, ctx.clock
        )
        self._call.args = dict(self._fixed)
        self._job: Job | None = None

    def _wake(self) -> None:
        self.ctx.wake()

    def _write(self, key: str, value: Any, writer: str) -> None:
        self.ctx.blackboard.set(key, value, writer)
        self._written.add(key)

    def update(self) -> Status:
        job = self._job
        fresh = job is None
        if job is None:
            try:
                job = self._start()
            except Exception as exc:  # the operation's fault: FAILURE of this node, never a crash
                return self.fail(_error_text(exc), _error_type(exc))
        try:
            # A plain Job's poll() is its status: read it without the call (the tick path of
            # every operation that answers at once).
            if job.__class__ is Job:
                status = job._status
            elif isinstance(job, Job):
                status = job.poll()
            else:
                raise TypeError(f"start() returned {job!r}; expected a Job (Job.done() when done)")
            if status is RUNNING:
                if fresh:
                    self._job = job
                    job.bind_wake(self.ctx.wake)
                return RUNNING
            if not fresh:
                self._job = None
            if status is SUCCESS:
                if job.outputs:
                    for port, value in job.outputs.items():
                        self._call.write(port, value)
                return self._succeeded(job.message)
        except Exception as exc:
            self._job = None
            return self.fail(_error_text(exc), _error_type(exc))
        return self.fail(job.message or ("false" if self.is_condition else "failed"), job.error)

    def _start(self) -> Job:
        call = self._call
        if self._refs:
            board = self.ctx.blackboard
            args = dict(self._fixed)
            for port, key, spec in self._refs:
                value = board.get(key, MISSING)
                if value is MISSING:
                    raise OperationFailed(
                        f"parameter {key!r} (for {port!r}) has no value yet",
                        ErrorType.INVALID_INPUT,
                    )
                args[port] = value if spec is None else read_reference(spec, key, value)
            call.args = args
        if self._is_query:
            self._written.clear()
        return self.operation.start(call)

    def _succeeded(self, message: str) -> Status:
        if self._is_query:
            missing = [k for k in self._call.outputs.values() if k not in self._written]
            if missing:
                return self.fail(f"the query wrote no value for {', '.join(missing)}")
        self.message = message
        return SUCCESS

    def on_halt(self) -> None:
        job = self._job
        self._job = None
        if job is not None:
            job.cancel()


class Wait(Node):
    """RUNNING for ``seconds`` of the tree's clock, then SUCCESS."""

    kind = "wait"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", seconds: float = 1.0
    ) -> None:
        super().__init__(ctx, node_id, name)
        if seconds < 0:
            raise ValueError(f"wait needs a duration of at least 0 s, not {seconds}")
        self.seconds = seconds
        self._deadline: float | None = None

    def update(self) -> Status:
        now = self.ctx.clock()
        if self._deadline is None:
            self._deadline = now + self.seconds
        if now >= self._deadline:
            return SUCCESS
        return RUNNING

    def on_reset(self) -> None:
        self._deadline = None


class ScriptLeaf(Node):
    """BehaviorTree.CPP's Script (SUCCESS once the script ran) or ScriptCondition (SUCCESS
    when the script's value is true, FAILURE when false); both in one tick.

    A script that fails while it runs (a missing entry, a value of the wrong type) fails the
    node with ``invalid_input`` and the line and column in the message; BehaviorTree.CPP
    throws there instead.

    Args:
        ctx: the tree's context.
        node_id: the runtime id (the writer of its blackboard writes).
        name: label.
        code: the script (parsed here: a syntax error raises ScriptSyntaxError).
        condition: True for a ScriptCondition.
        key: a name in the script -> its blackboard key (the scope it runs in).
        enums: names that read as integers.
    """

    kind = "script"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        code: str,
        *,
        condition: bool = False,
        key: Callable[[str], str] | None = None,
        enums: Mapping[str, int] | None = None,
    ) -> None:
        self.kind = "script_condition" if condition else "script"
        super().__init__(ctx, node_id, name)
        self.is_condition = condition
        self.script = parse_script(code)
        self._env = ScriptEnv(ctx.blackboard, enums, key=key, writer=node_id)

    def update(self) -> Status:
        try:
            if self.is_condition:
                return SUCCESS if self.script.check(self._env) else self.fail("false")
            self.script.run(self._env)
        except ScriptRunError as exc:
            return self.fail(f"script {exc}", ErrorType.INVALID_INPUT)
        return SUCCESS
