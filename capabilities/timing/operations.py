"""Operations of the timing capability: ``wait_until`` (the engine's Wait node waits a time).

``wait_until`` evaluates another condition operation once per tick until it is true or the
time is up, counting on the cell's clock (``call.clock()``: simulated time on the simulated
cell), so a plan waits the same simulated seconds however fast the simulation runs.
Validation checks the ``condition`` port (``names_kind``): the named operation exists, is a
condition, can run on the cell and needs no inputs.
"""

from __future__ import annotations

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import InPort, OperationKind, manifest, text
from capabilities.timing.until import ConditionRunner, OperationsLookup, WaitUntilJob
from engine.operations import Job, OperationCall
from engine.types import ParamType

__all__ = ["CONDITION", "TIMEOUT", "WaitUntil", "capability"]

CAP = "timing"

CONDITION = text(
    "condition",
    names_kind=OperationKind.CONDITION,
    doc="id of a condition operation (e.g. gripper.is_holding); its inputs take their defaults",
)
TIMEOUT = InPort[float](
    "timeout",
    (ParamType.DURATION, ParamType.NUMBER),
    default=10.0,
    unit="s",
    doc="how long to wait",
)


class WaitUntil:
    """timing.wait_until: polls a condition operation of the same registry."""

    MANIFEST = manifest(
        CAP,
        "wait_until",
        OperationKind.ACTION,
        "Checks a condition every tick; succeeds when it holds, fails when the time is up.",
        CONDITION,
        TIMEOUT,
    )

    def __init__(self, env: CapabilityEnv) -> None:
        self._lookup = OperationsLookup(env)

    def start(self, call: OperationCall) -> Job:
        op_id = call.input(CONDITION).strip()
        runner = ConditionRunner(self._lookup.source(), op_id, call)
        return WaitUntilJob(runner, call.clock, call.input(TIMEOUT))


def capability() -> Capability:
    """The timing capability (requires nothing)."""
    cap = Capability(CAP, "Waiting until a condition holds.")
    cap.add(WaitUntil)
    return cap
