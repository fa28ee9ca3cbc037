"""Operations of the timing capability: ``wait_until`` (the engine's Wait node waits a time).

``wait_until`` evaluates another condition operation once per tick until it is true or the
time is up, counting on the cell's clock (``call.clock()``: simulated time on the simulated
cell), so a plan waits the same simulated seconds however fast the simulation runs.
Validation checks the ``condition`` port (``names_kind``): the named operation exists, is a
condition, can run on the cell and needs no inputs.
"""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.kit import manifest
from capabilities.timing.until import ConditionRunner, OperationsLookup, WaitUntilJob
from engine.operations import Job, OperationCall, OperationKind, PortSpec
from engine.types import ParamType

__all__ = ["WAIT_UNTIL", "capability"]

CAP = "timing"

WAIT_UNTIL = manifest(
    CAP,
    "wait_until",
    OperationKind.ACTION,
    "Checks a condition every tick; succeeds when it holds, fails when the time is up.",
    PortSpec(
        "condition",
        (ParamType.TEXT,),
        names_kind=OperationKind.CONDITION,
        doc="id of a condition operation (e.g. gripper.is_holding); its inputs take their defaults",
    ),
    PortSpec(
        "timeout",
        (ParamType.DURATION, ParamType.NUMBER),
        default=10.0,
        unit="s",
        doc="how long to wait",
    ),
)


class WaitUntil:
    """timing.wait_until: polls a condition operation of the same registry."""

    def __init__(self, lookup: OperationsLookup) -> None:
        self._lookup = lookup

    def start(self, call: OperationCall) -> Job:
        op_id = call.input("condition").strip()
        runner = ConditionRunner(self._lookup.source(), op_id, call)
        return WaitUntilJob(runner, call.clock, call.input("timeout"))


def capability() -> Capability:
    """The timing capability (requires nothing)."""
    cap = Capability(CAP, "Waiting until a condition holds.")
    cap.add(WAIT_UNTIL, lambda env: WaitUntil(OperationsLookup(env)))
    return cap
