"""Operations of the debug capability: succeed, fail, run for N ticks, set, check, log.

They need no cell, so a plan built from them runs anywhere: the paper's Figure 3 can be
tried without a robot, and every node kind has an example plan.
"""

from __future__ import annotations

from typing import Any

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import manifest
from engine.error_types import ErrorType
from engine.operations import (
    Direction,
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    OperationManifest,
    PortSpec,
)
from engine.status import FAILURE, RUNNING, SUCCESS, Status
from engine.types import ParamType

__all__ = ["capability"]

CAP = "debug"
ANY = (ParamType.ANY,)
ALL_TYPES = (*(t for t in ParamType if t is not ParamType.ANY), ParamType.ANY)


class _Succeed:
    def start(self, call: OperationCall) -> Job:
        return Job.done()


class _Fail:
    def start(self, call: OperationCall) -> Job:
        error = ErrorType(str(call.input("error") or ErrorType.FAILED.value))
        raise OperationFailed(str(call.input("message") or "failed on purpose"), error)


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
        return self._then


def _then_status(value: str) -> Status:
    return SUCCESS if value == "SUCCESS" else FAILURE  # the port's choices


class _Running:
    def start(self, call: OperationCall) -> Job:
        ticks = int(call.input("ticks"))
        if ticks < 0:
            raise OperationFailed(f"ticks must be 0 or more, not {ticks}")
        return _TickJob(ticks, _then_status(call.input("then")), call.input("message"))


class _PretendMove:
    def start(self, call: OperationCall) -> Job:
        call.log(f"moving to {call.input('target')}")
        return _TickJob(int(call.input("ticks")), SUCCESS, "")


class _SetParam:
    def start(self, call: OperationCall) -> Job:
        call.write("name", call.input("value"))
        return Job.done()


class _Query:
    def start(self, call: OperationCall) -> Job:
        call.write("result", call.input("value"))
        return Job.done()


class _CheckParam:
    def start(self, call: OperationCall) -> Job:
        return Job.answer(bool(call.input("value") == call.input("expected")))


class _Condition:
    def start(self, call: OperationCall) -> Job:
        return Job.answer(bool(call.input("result")))


class _SucceedAfter:
    """False the first N times it is evaluated, true afterwards (state kept per leaf)."""

    def __init__(self) -> None:
        self.evaluations = 0

    def start(self, call: OperationCall) -> Job:
        self.evaluations += 1
        return Job.answer(self.evaluations > int(call.input("failures")))


class _Log:
    def start(self, call: OperationCall) -> Job:
        call.log(call.input("message"))
        return Job.done()


def _maker(cls: type) -> Any:
    def make(env: CapabilityEnv) -> Any:
        return cls()

    return make


def capability() -> Capability:
    """The debug capability with all its operations."""
    cap = Capability(CAP, "Operations for trying plans without a robot.")
    ticks = PortSpec("ticks", (ParamType.NUMBER,), default=3, doc="ticks spent RUNNING")
    entries: list[tuple[OperationManifest, type]] = [
        (manifest(CAP, "succeed", OperationKind.ACTION, "Succeeds at once."), _Succeed),
        (
            manifest(
                CAP,
                "fail",
                OperationKind.ACTION,
                "Fails at once with a message and an error type (a Catch can take it).",
                PortSpec("message", (ParamType.TEXT,), default="failed on purpose", doc="why"),
                PortSpec(
                    "error",
                    (ParamType.TEXT,),
                    default=ErrorType.FAILED.value,
                    doc="the type of the failure",
                    choices=tuple(t.value for t in ErrorType),
                ),
            ),
            _Fail,
        ),
        (
            manifest(
                CAP,
                "running",
                OperationKind.ACTION,
                "Runs for a number of ticks, then succeeds or fails.",
                ticks,
                PortSpec(
                    "then",
                    (ParamType.TEXT,),
                    default="SUCCESS",
                    doc="status at the end",
                    choices=("SUCCESS", "FAILURE"),
                ),
                PortSpec("message", (ParamType.TEXT,), default="", doc="failure message"),
            ),
            _Running,
        ),
        (
            manifest(
                CAP,
                "pretend_move",
                OperationKind.ACTION,
                "Pretends to move to a pose for some ticks.",
                PortSpec("target", (ParamType.POSE, ParamType.WAYPOINT), doc="where to go"),
                ticks,
            ),
            _PretendMove,
        ),
        (
            manifest(
                CAP,
                "set_param",
                OperationKind.ACTION,
                "Writes a value to a named parameter.",
                PortSpec("value", ALL_TYPES, doc="the value"),
                PortSpec("name", ANY, Direction.OUT, doc="the parameter written"),
            ),
            _SetParam,
        ),
        (
            manifest(
                CAP,
                "query",
                OperationKind.QUERY,
                "Answers with a given value (a stand-in query).",
                PortSpec("value", ALL_TYPES, doc="the answer"),
                PortSpec("result", ANY, Direction.OUT, doc="where the answer goes"),
            ),
            _Query,
        ),
        (
            manifest(
                CAP,
                "check_param",
                OperationKind.CONDITION,
                "True when a parameter equals a value.",
                PortSpec("value", ALL_TYPES, doc="the parameter (a reference)"),
                PortSpec("expected", ALL_TYPES, doc="the value it should have"),
            ),
            _CheckParam,
        ),
        (
            manifest(
                CAP,
                "condition",
                OperationKind.CONDITION,
                "True or false, as set.",
                PortSpec("result", (ParamType.BOOL,), default=True, doc="the answer"),
            ),
            _Condition,
        ),
        (
            manifest(
                CAP,
                "succeed_after",
                OperationKind.CONDITION,
                "False the first N times it is checked, then true (e.g. an object that appears).",
                PortSpec("failures", (ParamType.NUMBER,), default=2, doc="how many false answers"),
            ),
            _SucceedAfter,
        ),
        (
            manifest(
                CAP,
                "log",
                OperationKind.ACTION,
                "Writes a message to the run's log.",
                PortSpec("message", (ParamType.TEXT,), doc="the message"),
            ),
            _Log,
        ),
    ]
    for made, cls in entries:
        cap.add(made, _maker(cls))
    return cap
