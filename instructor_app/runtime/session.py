"""Which cell the Instructor works with, and the capability registry made for it.

Opening a cell can take long: the simulated cell starts its physics and renders its
cameras, a real cell connects to the robot's controller (up to its connect timeout against
a host that does not answer). The window therefore opens cells with
:meth:`CellSession.open_in_background`: the opener runs on a worker thread (one opening at a
time) and its result comes back to the GUI thread through a queued signal (as the teaching
commands' results do in ``teach.py``), where the registry is swapped and the panels told.
Until then the cell that was open stays in use, and it stays in use when the new one fails.
:meth:`CellSession.open` does the same while the caller waits (tests, scripts).
"""

from __future__ import annotations

import contextlib
import itertools
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QObject, Signal

from capabilities.base import CapabilityRegistry, Cell
from capabilities.cell_features import ClosableCell
from capabilities.cells import CELL_NAMES, CellError, is_cell_file, open_cell
from capabilities.robot.cell_robot import read_robot
from engine.json_reader import JsonFileError, JsonReader, read_json_file

__all__ = ["CellSession", "CellOpener", "RegistryFactory", "opening_words"]

CellOpener = Callable[..., ClosableCell]
RegistryFactory = Callable[[Cell | None], CapabilityRegistry]


def _default_registry(cell: Cell | None) -> CapabilityRegistry:
    return CapabilityRegistry(cell=cell)


def opening_words(name: str) -> str:
    """What opening the cell ``name`` does, for the status bar ("Connecting to 10.0.0.5…").

    Reads a cell file's ``robot`` block only (a small JSON file, on the caller's thread); a
    file that cannot be read is named as it is, and its error comes when it is opened.
    """
    if name == "sim":
        return "Starting the simulated cell…"
    if name == "none":
        return "Opening no cell…"
    if not is_cell_file(name):
        return f"Opening the {name} cell…"
    try:  # the robot block only: the whole configuration would import the simulator here
        robot = read_robot(JsonReader(read_json_file(name, "cell file"), name))
    except JsonFileError:
        return f"Opening {Path(name).name}…"
    if robot.kind == "ur":
        return f"Connecting to {robot.host}…"
    return f"Starting the simulated cell of {Path(name).name}…"


@dataclass(frozen=True)
class _Arrival:
    """What the worker thread hands back: the opened cell, or why it did not open."""

    name: str
    cell: ClosableCell | None
    registry: CapabilityRegistry | None
    error: str
    generation: int
    scene: str | None  # the scene it was opened with


def _is_sim(cell: ClosableCell | None) -> bool:
    """True for a simulated cell (built in or from a cell file): it has a scene."""
    return cell is not None and cell.name == "sim"


class CellSession(QObject):
    """The cell in use ("sim", "none" or a cell file) and its registry.

    Args:
        name: the cell to open first (nothing is opened until :meth:`open`).
        seed: scene seed of the simulated cell.
        speed: real-time factor of the simulated cell (1.0 real time; None as fast as
            possible).
        scene: scene of the simulated cell when a plan names none (None: the cell's default);
            :meth:`use_scene` picks a plan's.
        opener: opens a cell by name (tests may inject a fake); called on the worker thread
            by :meth:`open_in_background`.
        registry_factory: makes the registry for an open cell.

    Signals:
        cell_opening(str, str): a background opening started: the cell's name and what it
            does, in words ("Connecting to 10.0.0.5…").
        cell_changed(str): a cell was opened (its name).
        registry_changed(object): the new CapabilityRegistry; panels rebuild from it.
        cell_failed(str): a cell could not be opened (the message); the cell that was open
            stays in use ("none" when there was none).
        cell_ready(bool): an opening ended (True: the cell asked for is in use); what tests
            and ``--screenshot`` wait for.
    """

    cell_opening = Signal(str, str)
    cell_changed = Signal(str)
    registry_changed = Signal(object)
    cell_failed = Signal(str)
    cell_ready = Signal(bool)
    _arrived = Signal(object)  # worker -> GUI thread (queued: the session lives there)

    def __init__(
        self,
        name: str = "sim",
        seed: int = 0,
        speed: float | None = 1.0,
        scene: str | None = None,
        opener: CellOpener = open_cell,
        registry_factory: RegistryFactory = _default_registry,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self.name = name
        self.seed = seed
        self.speed = speed
        self.default_scene = scene  # for a plan that names no scene
        self.scene = scene  # the one the simulated cell opens with
        self._opener = opener
        self._registry_factory = registry_factory
        self.cell: ClosableCell | None = None
        self.registry: CapabilityRegistry = registry_factory(None)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="costar-cell-close")
        self._generations = itertools.count(1)
        self._generation = 0  # the opening whose result is still wanted
        self._opening = ""  # the cell being opened in the background ("" when none)
        self._arrived.connect(self._on_arrived)

    @staticmethod
    def cell_names() -> tuple[str, ...]:
        return CELL_NAMES

    @property
    def opening(self) -> str:
        """The cell being opened in the background ("" when none is)."""
        return self._opening

    # ------------------------------------------------------------------ opening

    def open(self, name: str | None = None) -> bool:
        """Open ``name`` (default: the one given at creation) while the caller waits, then
        close the cell that was open.

        Returns False when the cell failed to open (``cell_failed`` said why; the cell that
        was open stays in use, "none" when there was none) or while another opens in the
        background.
        """
        wanted = name or self.name
        if self._opening:
            self.cell_failed.emit(f"the {self._opening} cell is still opening; try again then")
            return False
        try:
            cell = self._opener(wanted, seed=self.seed, scene=self.scene, speed=self.speed)
        except CellError as exc:
            return self._failed(str(exc))
        self._use(wanted, cell, close_old_in_background=False)
        self.cell_ready.emit(True)
        return True

    def open_in_background(self, name: str | None = None) -> bool:
        """Start opening ``name`` on the worker thread; returns at once.

        The result arrives on the GUI thread: ``cell_changed`` and ``registry_changed`` when
        it opened, ``cell_failed`` when not, then ``cell_ready``. Returns False (and opens
        nothing) while another cell is still opening: one opening at a time.
        """
        wanted = name or self.name
        if self._opening:
            return False
        self._opening = wanted
        self._generation = generation = next(self._generations)
        self.cell_opening.emit(wanted, opening_words(wanted))
        # A daemon thread of its own, not the pool: quitting must not wait for a connect to a
        # robot that does not answer (the pool's threads are joined at exit).
        threading.Thread(
            target=self._open_on_worker,
            args=(wanted, generation, self.scene),
            name="costar-cell-open",
            daemon=True,
        ).start()
        return True

    def _open_on_worker(self, wanted: str, generation: int, scene: str | None) -> None:
        cell, registry, error = None, None, ""
        try:
            cell = self._opener(wanted, seed=self.seed, scene=scene, speed=self.speed)
            # here too: the first registry imports every capability (over half a second)
            registry = self._registry_factory(cell)
        except CellError as exc:
            error = str(exc)
        except Exception as exc:  # an opener's bug must not leave the window waiting
            error = f"the {wanted} cell did not open: {type(exc).__name__}: {exc}"
        if cell is not None and (error or generation != self._generation):
            cell.close()  # it failed after opening, or was closed meanwhile: nobody wants it
            cell = None
        if generation != self._generation:
            return
        with contextlib.suppress(RuntimeError):  # the session is gone: nobody to tell
            self._arrived.emit(_Arrival(wanted, cell, registry, error, generation, scene))

    def _on_arrived(self, arrival: object) -> None:
        """(GUI thread) The worker's result: use the cell, or keep the old one and say why."""
        assert isinstance(arrival, _Arrival)
        if arrival.generation != self._generation:  # closed after the worker looked
            if arrival.cell is not None:
                self._pool.submit(arrival.cell.close)
            return
        self._opening = ""
        if arrival.error:
            self._failed(arrival.error)
            return
        self._use(arrival.name, arrival.cell, True, arrival.registry)
        if arrival.scene != self.scene and _is_sim(arrival.cell):
            # a plan chose another scene while this one opened: open that one (Run waits)
            self.open_in_background(arrival.name)
            return
        self.cell_ready.emit(True)

    def _failed(self, message: str) -> bool:
        self.cell_failed.emit(message)
        if self.cell is None:  # nothing to fall back to: the cell without a robot
            self._use("none", self._opener("none", seed=self.seed), close_old_in_background=False)
        self.cell_ready.emit(False)
        return False

    def _use(
        self,
        name: str,
        cell: ClosableCell | None,
        close_old_in_background: bool,
        registry: CapabilityRegistry | None = None,
    ) -> None:
        """Make ``cell`` the one in use with ``registry`` (made here when None), tell the
        views, then release the one before.
        """
        old, self.cell, self.name = self.cell, cell, name
        self.registry = registry if registry is not None else self._registry_factory(cell)
        self.cell_changed.emit(name)
        self.registry_changed.emit(self.registry)
        if old is not None and old is not cell:
            if close_old_in_background:  # a real cell's close joins its I/O thread
                self._pool.submit(old.close)
            else:
                old.close()

    def reset(self) -> bool:
        """Put the cell back to its start, with a fresh registry so that no capability keeps
        state of an earlier run. The simulated cell is opened again with the same scene and
        seed (robot at home, objects where the seed places them); a cell with a real robot
        is not reconnected (nothing puts a real robot back): only its registry is new.
        Returns as :meth:`open`; False while a cell opens in the background.
        """
        if self._opening:
            return False
        if self.cell is not None and not _is_sim(self.cell):
            self._use(self.name, self.cell, close_old_in_background=False)
            return True
        cell, self.cell = self.cell, None
        if cell is not None:
            cell.close()
        return self.open(self.name)

    def use_scene(self, scene: str | None) -> bool:
        """Make ``scene`` (a plan's; "" or None: the default) the scene the simulated cell
        opens with, and reopen the simulated cell in the background when it holds another
        (as :meth:`open_in_background`). True when a reopening started.
        """
        wanted = scene or self.default_scene
        if wanted == self.scene:
            return False
        self.scene = wanted
        if not _is_sim(self.cell) or self._opening:
            return False  # the next opening or reset uses it
        return self.open_in_background(self.name)

    def clock(self) -> Callable[[], float] | None:
        """The open cell's clock (simulated time on the simulated cell), None if none open."""
        return self.cell.clock if self.cell is not None else None

    def close(self) -> None:
        """Release the open cell (its threads) and forget an opening under way (the worker
        closes what it opened); safe to call twice.
        """
        self._generation = next(self._generations)
        self._opening = ""
        cell, self.cell = self.cell, None
        if cell is not None:
            cell.close()
