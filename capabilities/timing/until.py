"""The machinery of ``timing.wait_until``: find and run another condition operation.

The condition comes from the registry that made the wait_until operation
(``CapabilityEnv.operations``), so it sees exactly the capabilities of the same cell.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from capabilities.base import CapabilityEnv
from engine.error_types import ErrorType
from engine.operations import (
    Job,
    Operation,
    OperationCall,
    OperationFailed,
    OperationKind,
    OperationNotFound,
    OperationSource,
    typed_input,
)
from engine.status import FAILURE, RUNNING, SUCCESS, Status

__all__ = ["ConditionRunner", "OperationsLookup", "WaitUntilJob"]


class OperationsLookup:
    """Finds the operation registry for an operation that runs other operations."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._env = env
        self._found: OperationSource | None = None

    def source(self) -> OperationSource:
        """The registry the operation was made by."""
        if self._found is None:
            given = self._env.operations
            if given is None:
                raise OperationFailed("wait_until was made outside a capability registry")
            self._found = given
        return self._found


class ConditionRunner:
    """One evaluation at a time of a condition operation, with its ports at their defaults."""

    def __init__(self, source: OperationSource, op_id: str, parent: OperationCall) -> None:
        if not op_id:  # a fixed id was checked by validation; one read from a name was not
            raise OperationFailed("wait_until needs the id of a condition operation")
        try:
            manifest = source.manifest(op_id)
        except OperationNotFound as exc:
            raise OperationFailed(f"there is no operation {op_id!r}") from exc
        if manifest.kind is not OperationKind.CONDITION:
            kind = manifest.kind.value
            article = "an" if kind[0] in "aeiou" else "a"
            raise OperationFailed(f"{op_id} is {article} {kind}, not a condition")
        availability = source.availability(op_id)
        if not availability.available:
            raise OperationFailed(f"{op_id} cannot run on this cell: {availability.reason}")
        needed = [p.name for p in manifest.inputs if p.required]
        if needed:
            raise OperationFailed(
                f"{op_id} needs {', '.join(needed)}, which wait_until cannot give it"
            )
        self.op_id = op_id
        self._operation: Operation = source.create(op_id)
        self._call = OperationCall(
            parent.node_id,
            f"{parent.node_name} ({op_id})",
            {},
            _no_write,
            lambda _node, message: parent.log(message),
            parent.wake,
            parent.clock,
        )
        self._call.args = {p.name: typed_input(p, p.default) for p in manifest.inputs}
        self._job: Job | None = None

    def check(self) -> bool | None:
        """True or False once an evaluation is done; None while one is still running."""
        if self._job is None:
            self._job = self._operation.start(self._call)
        status = self._job.poll()
        if status is RUNNING:
            return None
        self._job = None
        return status is SUCCESS

    def cancel(self) -> None:
        job, self._job = self._job, None
        if job is not None:
            job.cancel()


def _no_write(key: str, value: Any, writer: str) -> None:
    del key, value, writer  # a condition has no outputs


class WaitUntilJob(Job):
    """Checks the condition at each poll (one per tick) until true or past the deadline."""

    def __init__(self, runner: ConditionRunner, clock: Callable[[], float], timeout: float) -> None:
        super().__init__(on_cancel=runner.cancel)
        self._runner = runner
        self._clock = clock
        self._timeout = timeout
        self._deadline = clock() + timeout

    def poll(self) -> Status:
        if self._status is not RUNNING:
            return self._status
        try:
            result = self._runner.check()
        except OperationFailed as exc:
            self.fail(f"{self._runner.op_id}: {exc}", exc.error)
            return FAILURE
        except Exception as exc:  # the condition's bug fails this node, never the tick
            self.fail(f"{self._runner.op_id}: {type(exc).__name__}: {exc}", ErrorType.ERROR)
            return FAILURE
        if result:
            self.succeed(f"{self._runner.op_id} became true")
        elif self._clock() >= self._deadline:
            self._runner.cancel()
            self.fail(
                f"timed out after {self._timeout:g} s waiting for {self._runner.op_id}",
                ErrorType.TIMEOUT,
            )
        return self._status
