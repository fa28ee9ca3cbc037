"""Operations of the debug capability: succeed, fail, run for N ticks, set, check, log.

They need no cell, so a plan built from them runs anywhere: the paper's Figure 3 can be
tried without a robot, and every node kind has an example plan.
"""

from __future__ import annotations

from typing import Any, ClassVar

from capabilities.base import Capability, CapabilityEnv, OperationClass
from capabilities.kit import (
    InPort,
    OperationKind,
    flag,
    manifest,
    number,
    output,
    text,
    variant,
)
from engine.error_types import ErrorType
from engine.operations import Job, OperationCall, OperationFailed, PortSpec
from engine.status import FAILURE, RUNNING, SUCCESS, Status
from engine.types import ParamType, Pose, Waypoint

__all__ = ["capability"]

CAP = "debug"
ALL_TYPES = (*(t for t in ParamType if t is not ParamType.ANY), ParamType.ANY)
TICKS = number("ticks", 3, doc="ticks spent RUNNING")


class _Debug:
    """An operation that needs nothing from the cell."""

    def __init__(self, env: CapabilityEnv) -> None:
        pass


class Succeed(_Debug):
    """debug.succeed."""

    MANIFEST = manifest(CAP, "succeed", OperationKind.ACTION, "Succeeds at once.")

    def start(self, call: OperationCall) -> Job:
        return Job.done()


class Fail(_Debug):
    """debug.fail: raises OperationFailed with the message and error type."""

    MESSAGE = text("message", "failed on purpose", doc="why")
    ERROR = text(
        "error",
        ErrorType.FAILED.value,
        doc="the type of the failure",
        choices=tuple(t.value for t in ErrorType),
    )
    MANIFEST = manifest(
        CAP,
        "fail",
        OperationKind.ACTION,
        "Fails at once with a message and an error type (a Catch can take it).",
        MESSAGE,
        ERROR,
    )

    def start(self, call: OperationCall) -> Job:
        error = ErrorType(str(call.input(self.ERROR) or ErrorType.FAILED.value))
        raise OperationFailed(str(call.input(self.MESSAGE) or "failed on purpose"), error)


class _TickJob(Job):
    """RUNNING for a number of polls, then the given status."""

    def __init__(self, ticks: int, then: Status, message: str) -> None:
        super().__init__()
        self._left = ticks
        self._then = then
        self._final_message = message

    def poll(self) -> Status:
        if self._left > 0:
            self._left -= 1
            return RUNNING
        if self._then is FAILURE:
            self.message = self._final_message or "failed on purpose"
        else:
            self.message = self._final_message
        return self._then


def _then_status(value: str) -> Status:
    return SUCCESS if value == "SUCCESS" else FAILURE  # the port's choices


class Running(_Debug):
    """debug.running: RUNNING for some ticks, then the chosen status."""

    THEN = text("then", "SUCCESS", doc="status at the end", choices=("SUCCESS", "FAILURE"))
    MESSAGE = text("message", "", doc="the message it ends with (a failure's reason)")
    MANIFEST = manifest(
        CAP,
        "running",
        OperationKind.ACTION,
        "Runs for a number of ticks, then succeeds or fails.",
        TICKS,
        THEN,
        MESSAGE,
    )

    def start(self, call: OperationCall) -> Job:
        ticks = int(call.input(TICKS))
        if ticks < 0:
            raise OperationFailed(f"ticks must be 0 or more, not {ticks}")
        return _TickJob(ticks, _then_status(call.input(self.THEN)), call.input(self.MESSAGE))


class PretendMove(_Debug):
    """debug.pretend_move: logs the target and runs for some ticks."""

    TARGET = InPort[Pose | Waypoint](
        "target", (ParamType.POSE, ParamType.WAYPOINT), doc="where to go"
    )
    MANIFEST = manifest(
        CAP,
        "pretend_move",
        OperationKind.ACTION,
        "Pretends to move to a pose for some ticks.",
        TARGET,
        TICKS,
    )

    def start(self, call: OperationCall) -> Job:
        call.log(f"moving to {call.input(self.TARGET)}")
        return _TickJob(int(call.input(TICKS)), SUCCESS, "")


class _Echo(_Debug):
    """Writes its value to its one output: ``set_param`` to ``name``, ``query`` to ``result``."""

    VALUE: ClassVar[InPort[Any]]
    OUTPUT: ClassVar[str]

    @classmethod
    def of(
        cls, name: str, kind: OperationKind, doc: str, value_doc: str, output_port: PortSpec
    ) -> OperationClass:
        """The operation ``name`` that writes its ``value`` input to ``output_port``."""
        value = InPort[Any]("value", ALL_TYPES, doc=value_doc)
        made = manifest(CAP, name, kind, doc, value, output_port)
        return variant(cls, made, VALUE=value, OUTPUT=output_port.name)

    def start(self, call: OperationCall) -> Job:
        call.write(self.OUTPUT, call.input(self.VALUE))
        return Job.done()


SetParam = _Echo.of(
    "set_param",
    OperationKind.ACTION,
    "Writes a value to a named parameter.",
    "the value",
    output("name", ParamType.ANY, doc="the parameter written"),
)
Query = _Echo.of(
    "query",
    OperationKind.QUERY,
    "Answers with a given value (a stand-in query).",
    "the answer",
    output("result", ParamType.ANY, doc="where the answer goes"),
)


class CheckParam(_Debug):
    """debug.check_param: true when the value equals the expected one."""

    VALUE = InPort[Any]("value", ALL_TYPES, doc="the parameter (a reference)")
    EXPECTED = InPort[Any]("expected", ALL_TYPES, doc="the value it should have")
    MANIFEST = manifest(
        CAP,
        "check_param",
        OperationKind.CONDITION,
        "True when a parameter equals a value.",
        VALUE,
        EXPECTED,
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(bool(call.input(self.VALUE) == call.input(self.EXPECTED)))


class Condition(_Debug):
    """debug.condition: answers as set."""

    RESULT = flag("result", True, doc="the answer")
    MANIFEST = manifest(CAP, "condition", OperationKind.CONDITION, "True or false, as set.", RESULT)

    def start(self, call: OperationCall) -> Job:
        return Job.answer(bool(call.input(self.RESULT)))


class SucceedAfter(_Debug):
    """False the first N times it is evaluated, true afterwards (state kept per leaf)."""

    FAILURES = number("failures", 2, doc="how many false answers")
    MANIFEST = manifest(
        CAP,
        "succeed_after",
        OperationKind.CONDITION,
        "False the first N times it is checked, then true (e.g. an object that appears).",
        FAILURES,
    )

    def __init__(self, env: CapabilityEnv) -> None:
        self.evaluations = 0

    def start(self, call: OperationCall) -> Job:
        self.evaluations += 1
        return Job.answer(self.evaluations > int(call.input(self.FAILURES)))


class Log(_Debug):
    """debug.log: writes its message to the run's log."""

    MESSAGE = text("message", doc="the message")
    MANIFEST = manifest(
        CAP, "log", OperationKind.ACTION, "Writes a message to the run's log.", MESSAGE
    )

    def start(self, call: OperationCall) -> Job:
        call.log(call.input(self.MESSAGE))
        return Job.done()


def capability() -> Capability:
    """The debug capability with all its operations."""
    cap = Capability(CAP, "Operations for trying plans without a robot.")
    cap.add(
        Succeed,
        Fail,
        Running,
        PretendMove,
        SetParam,
        Query,
        CheckParam,
        Condition,
        SucceedAfter,
        Log,
    )
    return cap
