"""Operations as the engine sees them: manifests, the call an operation gets, and jobs.

A manifest describes an operation (id, kind, typed ports, doc) apart from the code that
runs it, as BehaviorTree.CPP keeps node manifests apart from node classes. The code is an
:class:`Operation`: ``start(call)`` begins the work and returns at once, either with a
finished status or with a :class:`Job` that the leaf polls each tick and can cancel.
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from engine.errors import EngineError
from engine.status import FAILURE, RUNNING, SUCCESS, Status
from engine.types import ParamType

__all__ = [
    "OperationKind",
    "Direction",
    "PortSpec",
    "OperationManifest",
    "OperationCall",
    "Operation",
    "OperationFactory",
    "Job",
    "OperationNotFound",
    "OperationSource",
    "Availability",
    "OperationFailed",
    "StartResult",
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
    """

    name: str
    types: tuple[ParamType, ...]
    direction: Direction = Direction.IN
    default: Any = None
    unit: str = ""
    doc: str = ""
    choices: tuple[str, ...] = ()

    @property
    def type(self) -> ParamType:
        return self.types[0]

    @property
    def required(self) -> bool:
        return self.direction is Direction.IN and self.default is None


@dataclass(frozen=True)
class OperationManifest:
    """What an operation is, for the palette, validation and ``costar ops``."""

    id: str
    kind: OperationKind
    doc: str
    capability: str
    ports: tuple[PortSpec, ...] = ()
    aliases: tuple[str, ...] = ()  # former ids that files may still use

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
    """What an operation gets when it starts: resolved inputs, a way to write outputs.

    One call object lives per leaf and is reused between starts (allocation in the tick
    path costs time); ``args`` is refreshed before each start.
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
        self.args: dict[str, Any] = {}
        self.node_id = node_id
        self.node_name = node_name
        self.outputs = dict(outputs)  # port name -> blackboard key
        self._writer = writer
        self._logger = logger
        self.wake = wake
        self.clock = clock

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


class Job:
    """Work that outlives one tick: finished from any thread, polled by the engine thread.

    Subclass and override :meth:`poll` for work that advances with ticks; or keep the base
    and call :meth:`succeed` / :meth:`fail` from the thread that does the work. Outputs
    given to ``succeed`` are written to the blackboard by the engine thread when it polls.
    """

    def __init__(self, on_cancel: Callable[[], None] | None = None) -> None:
        self._lock = threading.Lock()
        self._status = RUNNING
        self.message = ""
        self.outputs: dict[str, Any] = {}
        self._on_cancel = on_cancel
        self._cancelled = False
        self._on_done: Callable[[], None] | None = None

    def bind_wake(self, wake: Callable[[], None]) -> None:
        """Called by the leaf: ``wake`` runs when the job finishes, to tick again at once."""
        with self._lock:
            self._on_done = wake
            finished = self._status is not RUNNING
        if finished:
            wake()

    def _finish(self, status: Status, message: str, outputs: Mapping[str, Any] | None) -> None:
        with self._lock:
            if self._status is not RUNNING:
                return
            self.message = message
            if outputs:
                self.outputs.update(outputs)
            self._status = status
            wake = self._on_done
        if wake is not None:
            wake()

    def succeed(self, message: str = "", outputs: Mapping[str, Any] | None = None) -> None:
        """Finish with SUCCESS (first finish wins; later calls are ignored)."""
        self._finish(SUCCESS, message, outputs)

    def fail(self, message: str) -> None:
        """Finish with FAILURE and a message saying why."""
        self._finish(FAILURE, message, None)

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
            callback = self._on_cancel
        if callback is not None:
            callback()


StartResult = Status | bool | Job | None


class Operation(Protocol):
    """The code of one operation; one instance per leaf of a built tree.

    ``start`` must return quickly: True/SUCCESS or False/FAILURE when done at once, or a
    :class:`Job` for longer work. ``None`` counts as SUCCESS. Raising makes the node FAILURE
    with the exception's message.
    """

    def start(self, call: OperationCall) -> StartResult: ...


OperationFactory = Callable[[], Operation]


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
    """Raised by an operation to fail its node with exactly this message."""
