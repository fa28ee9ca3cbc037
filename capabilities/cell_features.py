"""What a cell may offer beyond the :class:`~capabilities.base.Cell` protocol, as typed protocols.

A cell has a name, interfaces and a clock (``capabilities.base.Cell``). The features below
are optional: the code that uses one asks ``isinstance(cell, HoldsRuns)`` (the protocols are
runtime-checkable) rather than probing for a method, so a cell declares what it offers by its
methods' names and types, and mypy checks both sides.

- :class:`ClosableCell`: a cell with a lifetime (what ``capabilities.cells.open_cell``
  returns): ``close()``, and a context manager that closes it; :class:`ClosesOnExit` is
  that context manager, for a class to inherit.
- :class:`HoldsRuns`: a cell that can stop on its own says why it cannot act
  (``capabilities.faults.hold_check`` turns it into the executor's hold check).
- :class:`ReportsStatus`: what the status bar shows of the robot (a :class:`CellStatus`).
- :class:`ClearsStop`: the operator's clear of what the status names.
- :class:`ShowsGroundTruth`: the simulator's ground truth, for its tests, scores and the 3D
  view's truth overlay only, never for an operation.
- :class:`RunsInLockstep`: a cell whose world goes on only with the engine's clock during a
  run (a simulated cell run as fast as it can); :func:`lockstep_of` gives the executor's.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import TracebackType
from typing import Protocol, Self, runtime_checkable

from capabilities.base import Cell
from engine.executor import Lockstep
from engine.types import Pose

__all__ = [
    "CellStatus",
    "ClearsStop",
    "ClosableCell",
    "ClosesOnExit",
    "HoldsRuns",
    "ReportsStatus",
    "RunsInLockstep",
    "SceneObjects",
    "ShowsGroundTruth",
    "lockstep_of",
]


@dataclass(frozen=True)
class CellStatus:
    """What the status bar shows of the robot: connection, robot mode, safety mode, program.

    Attributes:
        problem: why the robot cannot move ("" when it can).
        clear_action: the label of the operator's clear of that problem from here ("" when
            there is none now: it is cleared on the pendant, or not yet allowed).
        clear_wait: whole seconds before that clear is allowed (0: now); a UR refuses to
            unlock a protective stop in the first 5 s after it, so the button counts down.
        hint: how the operator clears the problem, in words ("clear it on the pendant or
            press Unlock protective stop"; "" when nothing is to be said).
    """

    connected: bool
    robot_mode: str
    safety_mode: str
    program: str
    problem: str
    clear_action: str = ""
    clear_wait: int = 0
    hint: str = ""


@runtime_checkable
class ClosableCell(Cell, Protocol):
    """A cell with a lifetime: closing it releases its threads and connections."""

    def close(self) -> None:
        """Release the cell (threads, connections); the arm halts first."""
        ...

    def __enter__(self) -> ClosableCell: ...

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None: ...


class ClosesOnExit:
    """A context manager that gives itself on entry and calls ``close()`` on exit.

    For a class with a lifetime (a cell, the UR emulator and its process): it defines
    ``close()``, and overrides ``__enter__`` only when entering also starts it.
    """

    def close(self) -> None:
        """Release what the object holds (threads, connections, processes)."""
        raise NotImplementedError

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


@runtime_checkable
class HoldsRuns(Protocol):
    """A cell that can stop on its own (a protective stop, a lost connection)."""

    def hold_reason(self) -> str:
        """Why the cell cannot act now, in ``capabilities.faults``' words; "" when it can."""
        ...


@runtime_checkable
class ReportsStatus(Protocol):
    """A cell with a robot controller to show in the status bar."""

    def status(self) -> CellStatus | None:
        """The robot's state now (None: nothing to show)."""
        ...


@runtime_checkable
class ClearsStop(Protocol):
    """A cell whose robot's stop the operator can clear from here."""

    def clear(self) -> None:
        """Clear what the status names (``CellStatus.clear_action``), on the cell's thread."""
        ...


class SceneObjects(Protocol):
    """The simulated scene as the ground truth names it."""

    @property
    def objects(self) -> Mapping[str, object]:
        """The scene's objects by name."""
        ...


@runtime_checkable
class ShowsGroundTruth(Protocol):
    """The simulated cell's ground truth: for tests, scores and the truth overlay only."""

    @property
    def scene(self) -> SceneObjects:
        """The simulated scene."""
        ...

    def truth_pose(self, name: str) -> Pose:
        """GROUND TRUTH of an object's pose."""
        ...


@runtime_checkable
class RunsInLockstep(Protocol):
    """A cell whose world can go on only with the engine's clock (``engine.executor``)."""

    def run_lockstep(self) -> Lockstep | None:
        """The lockstep a run's executor drives (None: the world goes on by itself)."""
        ...


def lockstep_of(cell: object) -> Lockstep | None:
    """The executor's lockstep with ``cell`` (None for a cell that is not in one)."""
    return cell.run_lockstep() if isinstance(cell, RunsInLockstep) else None
