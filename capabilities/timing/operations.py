"""Operations of the timing capability: ``wait`` and ``wait_until``.

Both count time on the cell's clock (``call.clock()``: simulated time on the simulated cell),
so a plan waits the same simulated seconds however fast the simulation runs. ``wait_until``
evaluates another condition operation once per tick until it is true or the time is up.
"""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.timing.until import ConditionRunner, OperationsLookup, WaitUntilJob
from engine.operations import (
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    OperationManifest,
    PortSpec,
    StartResult,
)
from engine.status import RUNNING, SUCCESS, Status
from engine.types import ParamType

__all__ = ["build_timing_capability", "WAIT", "WAIT_UNTIL"]

CAP = "timing"

WAIT = OperationManifest(
    f"{CAP}.wait",
    OperationKind.ACTION,
    "Waits a number of seconds on the cell's clock.",
    CAP,
    (
        PortSpec(
            "seconds", (ParamType.DURATION, ParamType.NUMBER), default=1.0, unit="s", doc="how long"
        ),
    ),
)
WAIT_UNTIL = OperationManifest(
    f"{CAP}.wait_until",
    OperationKind.ACTION,
    "Checks a condition every tick; succeeds when it holds, fails when the time is up.",
    CAP,
    (
        PortSpec(
            "condition", (ParamType.TEXT,),
            doc="id of a condition operation (e.g. gripper.is_holding); its inputs take their defaults",
        ),
        PortSpec("timeout", (ParamType.DURATION, ParamType.NUMBER), default=10.0, unit="s", doc="how long to wait"),
    ),
)  # fmt: skip


def _seconds(call: OperationCall, port: str) -> float:
    value = call.args.get(port)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
        raise OperationFailed(f"{port} must be a number of seconds, 0 or more, not {value!r}")
    return float(value)


class _WaitJob(Job):
    """RUNNING until the cell's clock reaches the deadline."""

    def __init__(self, call: OperationCall, seconds: float) -> None:
        super().__init__()
        self._clock = call.clock
        self._deadline = call.clock() + seconds

    def poll(self) -> Status:
        if self._status is RUNNING and self._clock() >= self._deadline:
            self.succeed()
        return self._status


class Wait:
    """timing.wait."""

    def start(self, call: OperationCall) -> StartResult:
        seconds = _seconds(call, "seconds")
        if seconds == 0:
            return SUCCESS
        return _WaitJob(call, seconds)


class WaitUntil:
    """timing.wait_until: polls a condition operation of the same registry."""

    def __init__(self, lookup: OperationsLookup) -> None:
        self._lookup = lookup

    def start(self, call: OperationCall) -> StartResult:
        op_id = str(call.args.get("condition", "")).strip()
        if not op_id:
            raise OperationFailed("wait_until needs the id of a condition operation")
        timeout = _seconds(call, "timeout")
        runner = ConditionRunner(self._lookup.source(), op_id, call)
        return WaitUntilJob(runner, call.clock, timeout)


def build_timing_capability() -> Capability:
    """The timing capability (requires nothing)."""
    cap = Capability(CAP, "Waiting: for a time, or until a condition holds.")
    cap.add(WAIT, lambda env: Wait())
    cap.add(WAIT_UNTIL, lambda env: WaitUntil(OperationsLookup(env)))
    return cap
