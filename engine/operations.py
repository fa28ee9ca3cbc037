"""Operations as the engine sees them: manifests, the call an operation gets, and jobs.

A manifest describes an operation (id, kind, typed ports, doc) apart from the code that
runs it, as BehaviorTree.CPP keeps node manifests apart from node classes. The code is an
:class:`Operation`: ``start(call)`` begins the work and returns at once, either with a
finished status or with a :class:`Job` that the leaf polls each tick and can cancel.
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Generic, Protocol, TypeVar

from engine.error_types import ErrorType
from engine.errors import EngineError
from engine.status import FAILURE, RUNNING, SUCCESS, Status
from engine.types import (
    JointConfig,
    ObjectModel,
    ParamType,
    Pose,
    Region,
    check_value,
    type_of_value,
)

__all__ = [
    "OperationKind",
    "BoundPort",
    "PortRule",
    "Direction",
    "PortSpec",
    "InPort",
    "number",
    "duration",
    "text",
    "flag",
    "pose",
    "joints",
    "region",
    "object_model",
    "OperationManifest",
    "OperationCall",
    "Operation",
    "Job",
    "OperationNotFound",
    "OperationSource",
    "Availability",
    "OperationFailed",
    "StartResult",
    "InputTypeError",
]


class OperationKind(str, enum.Enum):
    """The paper's three kinds of operation (section III-A)."""

    ACTION = "action"
    QUERY = "query"
    CONDITION = "condition"  # the paper's predicate


class Direction(str, enum.Enum):
    """Whether a port is read by the operation or written by it."""

    IN = "in"
    OUT = "out"


@dataclass(frozen=True)
class PortSpec:
    """One typed parameter of an operation.

    Attributes:
        name: the port's name, unique within the operation.
        types: accepted value types; the first is the one shown by default.
        direction: IN ports take a fixed value or a reference; OUT ports name the
            blackboard entry the operation writes.
        default: the value used when the plan leaves an IN port unbound (None: required).
        unit: the SI unit of a Number ("m", "rad", "m/s"), shown converted in the UI.
        doc: one line for the inspector and ``costar ops``.
        choices: allowed values of a Text port, if it is an enumeration.
        names_kind: set on a Text port whose value is the id of another operation, of
            this kind (``timing.wait_until``'s ``condition``): validation checks that such
            an operation exists, is of that kind and needs no inputs.
    """

    name: str
    types: tuple[ParamType, ...]
    direction: Direction = Direction.IN
    default: Any = None
    unit: str = ""
    doc: str = ""
    choices: tuple[str, ...] = ()
    names_kind: OperationKind | None = None

    @property
    def type(self) -> ParamType:
        return self.types[0]

    @property
    def required(self) -> bool:
        return self.direction is Direction.IN and self.default is None


T = TypeVar("T")


@dataclass(frozen=True, eq=False)
class InPort(PortSpec, Generic[T]):
    """An input port whose value the operation reads as a ``T`` (``call.input(SPEED)``).

    BehaviorTree.CPP's ``InputPort<T>``: the manifest lists it, and the operation reads it
    through the same object, so the type a reader gets is the port's. Made with the
    constructors below (:func:`number` gives an ``InPort[float]``); a port of several
    types says its union explicitly: ``InPort[Waypoint | Pose]("target", (...))``.
    """

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PortSpec) and _fields(self) == _fields(other)

    def __hash__(self) -> int:
        return hash(_fields(self))


def _fields(port: PortSpec) -> tuple[Any, ...]:
    return (
        port.name,
        port.types,
        port.direction,
        port.default,
        port.unit,
        port.doc,
        port.choices,
        port.names_kind,
    )


def number(
    name: str, default: float | None = None, *, unit: str = "", doc: str = ""
) -> InPort[float]:
    """A Number input (SI units; an integer is read as a float)."""
    return InPort(name, (ParamType.NUMBER,), default=default, unit=unit, doc=doc)


def duration(name: str, default: float | None = None, *, doc: str = "") -> InPort[float]:
    """A Duration input, in seconds."""
    return InPort(name, (ParamType.DURATION,), default=default, unit="s", doc=doc)


def text(
    name: str,
    default: str | None = None,
    *,
    doc: str = "",
    choices: tuple[str, ...] = (),
    names_kind: OperationKind | None = None,
) -> InPort[str]:
    """A Text input, one of ``choices`` when given."""
    return InPort(
        name,
        (ParamType.TEXT,),
        default=default,
        doc=doc,
        choices=choices,
        names_kind=names_kind,
    )


def flag(name: str, default: bool | None = None, *, doc: str = "") -> InPort[bool]:
    """A Bool input."""
    return InPort(name, (ParamType.BOOL,), default=default, doc=doc)


def pose(name: str, default: Pose | None = None, *, doc: str = "") -> InPort[Pose]:
    """A Pose input (world frame)."""
    return InPort(name, (ParamType.POSE,), default=default, doc=doc)


def joints(name: str, *, unit: str = "rad", doc: str = "") -> InPort[JointConfig]:
    """A JointConfig input."""
    return InPort(name, (ParamType.JOINTS,), unit=unit, doc=doc)


def region(name: str, *, doc: str = "") -> InPort[Region]:
    """A Region input (a sphere of space)."""
    return InPort(name, (ParamType.REGION,), doc=doc)


def object_model(name: str, *, doc: str = "") -> InPort[ObjectModel]:
    """An ObjectModel input (an object by its model name)."""
    return InPort(name, (ParamType.OBJECT,), doc=doc)


@dataclass(frozen=True)
class BoundPort:
    """What validation knows of one bound input port, for a :data:`PortRule`.

    Attributes:
        types: the types its value may have: the fixed value's type, or the types of what
            writes the reference (``(ParamType.ANY,)`` when that is not known).
        value: the fixed value, None for a reference.
        ref: the blackboard name it reads, None for a fixed value.
    """

    types: tuple[ParamType, ...]
    value: Any = None
    ref: str | None = None

    def may_be(self, ptype: ParamType) -> bool:
        """True when the value may be of ``ptype``."""
        return ptype in self.types or ParamType.ANY in self.types

    def only(self, ptype: ParamType) -> bool:
        """True when the value is surely of ``ptype``."""
        return set(self.types) == {ptype}


# A check across an operation's ports: given its bound inputs (port name -> BoundPort;
# unbound ports are absent), the (port, sentence) of each input it would ignore or cannot
# use with the others. The sentence names the port; validation adds the node.
PortRule = Callable[[Mapping[str, BoundPort]], Iterable[tuple[str, str]]]


@dataclass(frozen=True)
class OperationManifest:
    """What an operation is, for the palette, validation and ``costar ops``."""

    id: str
    kind: OperationKind
    doc: str
    capability: str
    ports: tuple[PortSpec, ...] = ()
    aliases: tuple[str, ...] = ()  # former ids that files may still use
    # Checks across ports (an input that some other input makes meaningless): validation
    # runs each on the node's bindings and reports what it returns as errors.
    rules: tuple[PortRule, ...] = field(default=(), compare=False)

    def port(self, name: str) -> PortSpec | None:
        for port in self.ports:
            if port.name == name:
                return port
        return None

    @property
    def inputs(self) -> tuple[PortSpec, ...]:
        return tuple(p for p in self.ports if p.direction is Direction.IN)

    @property
    def outputs(self) -> tuple[PortSpec, ...]:
        return tuple(p for p in self.ports if p.direction is Direction.OUT)


class OperationCall:
    """What an operation gets when it starts: its typed inputs, a way to write outputs.

    An operation reads each input with :meth:`input`, given the :class:`InPort` of its
    manifest (BehaviorTree.CPP's ``getInput<T>``; ``call.input(SPEED)`` is a float):
    the value is already of one of the port's types and in SI units (a Number or Duration
    is a float), fixed values were checked by validation and a reference's value was
    checked against the port's types when the leaf read it, so an operation does not
    check them again. One call object lives per leaf and is reused between starts
    (allocation in the tick path costs time); the inputs are refreshed before each start.
    """

    __slots__ = ("_logger", "_writer", "args", "clock", "node_id", "node_name", "outputs", "wake")

    def __init__(
        self,
        node_id: str,
        node_name: str,
        outputs: Mapping[str, str],
        writer: Callable[[str, Any, str], None],
        logger: Callable[[str, str], None],
        wake: Callable[[], None],
        clock: Callable[[], float],
    ) -> None:
        self.args: dict[str, Any] = {}  # port name -> typed value; read it with input()
        self.node_id = node_id
        self.node_name = node_name
        self.outputs = dict(outputs)  # port name -> blackboard key
        self._writer = writer
        self._logger = logger
        self.wake = wake
        self.clock = clock

    def input(self, port: InPort[T]) -> T:
        """The typed value of an input port (its default when the plan leaves it unbound).

        Raises:
            OperationFailed: the operation asked for a port its manifest does not have.
        """
        try:
            value: T = self.args[port.name]
        except KeyError:
            raise OperationFailed(f"{self.node_name!r} has no input {port.name!r}") from None
        return value

    def write(self, port: str, value: Any) -> None:
        """Write the value of an output port to the blackboard entry it is bound to.

        An output the plan does not store (validation only warns about it) is dropped: the
        operation cannot know which of its results the plan keeps, and must not fail for it.
        """
        key = self.outputs.get(port)
        if key is None:
            return
        self._writer(key, value, self.node_id)

    def log(self, message: str) -> None:
        """Add a line to the run's log, attributed to this node."""
        self._logger(self.node_id, message)


_NUMERIC = (ParamType.NUMBER, ParamType.DURATION)


def typed_input(port: PortSpec, value: Any) -> Any:
    """``value`` as the port's type: an int given to a Number or Duration port is a float."""
    if type(value) is int and any(t in _NUMERIC for t in port.types):
        return float(value)
    return value


def read_reference(port: PortSpec, key: str, value: Any) -> Any:
    """A value read from the blackboard for ``port``, checked against the port's types.

    Raises:
        InputTypeError: the value is of none of the port's types (or not one of its
            choices); the message names the port, the blackboard name, the expected and
            the actual type.
    """
    for ptype in port.types:
        if check_value(ptype, value):
            if port.choices and value not in port.choices:
                break
            return typed_input(port, value)
    raise InputTypeError(port, key, value)


class Job:
    """What ``start`` returns: work that finished at once, or that outlives one tick.

    Work done at once returns a finished job: :meth:`done`, :meth:`failed` or
    :meth:`answer` (a condition's true/false). Longer work subclasses and overrides
    :meth:`poll` for work that advances with ticks, or keeps the base and calls
    :meth:`succeed` / :meth:`fail` from the thread that does the work. Outputs given to
    ``succeed`` or ``done`` are written to the blackboard by the engine thread when it polls.
    """

    @staticmethod
    def done(message: str = "", outputs: Mapping[str, Any] | None = None) -> Job:
        """A job that already succeeded (shared when it carries nothing)."""
        if not message and not outputs:
            return _DONE
        job = Job()
        job.succeed(message, outputs)
        return job

    @staticmethod
    def failed(message: str = "", error: ErrorType = ErrorType.FAILED) -> Job:
        """A job that already failed with ``message`` (empty: the leaf says "failed").

        ``error`` is the failure's type, which a Catch node matches.
        """
        if not message and error is ErrorType.FAILED:
            return _FAILED
        job = Job()
        job.fail(message, error)
        return job

    @staticmethod
    def answer(value: bool, message: str = "") -> Job:
        """A condition's answer: SUCCESS when true, FAILURE (message "false") when not."""
        if message:
            return Job.done(message) if value else Job.failed(message)
        return _DONE if value else _FAILED

    def __init__(self, on_cancel: Callable[[], None] | None = None) -> None:
        self._lock = threading.Lock()
        self._status = RUNNING
        self.message = ""
        self.error = ErrorType.FAILED  # the type of a FAILURE
        self.outputs: dict[str, Any] = {}
        self._on_cancel = on_cancel
        self._cancelled = False
        self._on_done: Callable[[], None] | None = None

    def bind_wake(self, wake: Callable[[], None]) -> None:
        """Called by the leaf: ``wake`` runs when the job finishes, to tick again at once."""
        with self._lock:
            finished = self._status is not RUNNING
            if not finished:
                self._on_done = wake
        if finished:
            wake()

    def _finish(
        self,
        status: Status,
        message: str,
        outputs: Mapping[str, Any] | None,
        error: ErrorType = ErrorType.FAILED,
    ) -> None:
        with self._lock:
            if self._status is not RUNNING:
                return
            self.message = message
            self.error = error
            if outputs:
                self.outputs.update(outputs)
            self._status = status
            wake = self._on_done
        if wake is not None:
            wake()

    def succeed(self, message: str = "", outputs: Mapping[str, Any] | None = None) -> None:
        """Finish with SUCCESS (first finish wins; later calls are ignored)."""
        self._finish(SUCCESS, message, outputs)

    def fail(self, message: str, error: ErrorType = ErrorType.FAILED) -> None:
        """Finish with FAILURE, a message saying why and the failure's type."""
        self._finish(FAILURE, message, None, error)

    @property
    def finished(self) -> bool:
        return self._status is not RUNNING

    def poll(self) -> Status:
        """The job's status now: RUNNING, SUCCESS or FAILURE. Must not block."""
        return self._status

    def cancel(self) -> None:
        """Stop the work. Called at most once by the engine; must not raise or block long."""
        with self._lock:
            if self._cancelled:
                return
            self._cancelled = True
            if self._status is RUNNING:
                self._status = FAILURE
                self.message = "halted"
                self.error = ErrorType.HALTED
            callback = self._on_cancel
        if callback is not None:
            callback()


_DONE = Job()
_DONE.succeed()
_FAILED = Job()
_FAILED.fail("")

StartResult = Job  # the one thing ``start`` returns


class Operation(Protocol):
    """The code of one operation; one instance per leaf of a built tree.

    ``start`` must return quickly, always with a :class:`Job`: a finished one
    (``Job.done()``, ``Job.failed(message)``, ``Job.answer(flag)``) when the work is done at
    once, a running one for longer work. Raising makes the node FAILURE with the exception's
    message (:class:`OperationFailed`: exactly its message).
    """

    def start(self, call: OperationCall) -> StartResult: ...


class OperationNotFound(EngineError, LookupError):
    """No operation of that id (or alias) is registered."""


@dataclass(frozen=True)
class Availability:
    """Whether an operation can run here, and if not, why not."""

    available: bool = True
    reason: str = ""


class OperationSource(Protocol):
    """What the engine needs from a registry of operations (capabilities implement it)."""

    def manifest(self, op_id: str) -> OperationManifest:
        """The manifest of an id or alias; raises OperationNotFound."""
        ...

    def availability(self, op_id: str) -> Availability: ...

    def create(self, op_id: str) -> Operation:
        """A fresh instance of the operation's code for one leaf."""
        ...

    def aliases(self) -> Mapping[str, str]:
        """Former operation ids mapped to the current ones."""
        ...

    def manifests(self) -> list[OperationManifest]:
        """Every operation's manifest (for listings and "did you mean" hints)."""
        ...


class OperationFailed(EngineError):
    """Raised by an operation to fail its node with exactly this message and error type."""

    def __init__(self, message: str = "", error: ErrorType = ErrorType.FAILED) -> None:
        super().__init__(message)
        self.error = error


class InputTypeError(OperationFailed):
    """A reference's value is not of the type the reading port accepts."""

    def __init__(self, port: PortSpec, key: str, value: Any) -> None:
        self.port = port.name
        self.key = key
        expected = " or ".join(t.value for t in port.types)
        if port.choices:
            expected += f" (one of {', '.join(port.choices)})"
        actual = type_of_value(value).value
        super().__init__(
            f"input {port.name!r} reads {key!r}, which holds {actual} {_short(value)}; "
            f"expected {expected}",
            ErrorType.INVALID_INPUT,
        )


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
