"""Opening a cell by name or cell file: what ``costar run --cell NAME|FILE`` and the Instructor use.

A cell file (``*.cell.json``) with ``"robot": {"kind": "sim"}`` opens the simulated cell with
that configuration; with ``"robot": {"kind": "ur", "host": ...}`` it connects to that UR
controller (``capabilities.ur``, imported only then).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from capabilities.cell_features import ClosableCell, ClosesOnExit
from capabilities.collaboration.console import OperatorConsole
from capabilities.errors import CapabilityError

if TYPE_CHECKING:
    from capabilities.robot.cell_file import CellConfig

__all__ = [
    "CELL_NAMES",
    "DEFAULT_SCENE",
    "CellError",
    "ManagedCell",
    "cell_argument",
    "is_cell_file",
    "open_cell",
]

CELL_NAMES: tuple[str, ...] = ("none", "sim")
DEFAULT_SCENE = "cup_to_bin"  # the simulated cell's scene when none is named


class CellError(CapabilityError):
    """A cell could not be opened."""


class ManagedCell(ClosesOnExit):
    """A cell with a lifetime: a context manager that closes it.

    The ``none`` cell has no robot: only cell-free capabilities (``debug``) and the
    operator's console (``operator``: prompts and buttons) are there.
    """

    name = "none"

    def __init__(self) -> None:
        self._operator = OperatorConsole()

    @property
    def operator(self) -> OperatorConsole:
        """The operator's console (made here if a subclass skipped ``__init__``)."""
        if "_operator" not in self.__dict__:
            self._operator = OperatorConsole()
        return self._operator

    def interfaces(self) -> Mapping[str, Any]:
        return {"operator": self.operator}

    def clock(self) -> float:
        return time.monotonic()

    def close(self) -> None:
        """Release the cell (threads, connections)."""


def open_cell(
    name: str,
    seed: int = 0,
    start: bool = True,
    scene: str | None = None,
    speed: float | None = None,
    still_until_run: bool = False,
) -> ClosableCell:
    """The cell called ``name``, as a context manager.

    Args:
        name: "none" (no robot), "sim" (the pybullet cell; imported only when asked for) or
            the path of a cell file (``*.cell.json``).
        seed: randomisation seed of the simulated scene.
        start: begin the cell's threads (the simulated cell always starts: it needs its
            physics thread to answer anything).
        scene: scene name or path for the simulated cell (default: cup_to_bin).
        speed: real-time factor of the simulated cell (None: as fast as possible).
        still_until_run: a simulated cell run as fast as possible (in lockstep) stands still
            until a run's executor drives it (``SimCellSession``): a run then begins at
            simulated time 0 whatever its set-up took.
    """
    if name == "none":
        return ManagedCell()
    if is_cell_file(name):
        return _open_cell_file(Path(name), seed, scene, speed, still_until_run)
    if name == "sim":
        return _open_sim(seed, scene, speed, still_until_run)
    raise CellError(
        f"unknown cell {name!r}; cells: {', '.join(CELL_NAMES)}, or a cell file (*.cell.json)"
    )


def cell_argument(value: str) -> str:
    """A command line's ``--cell``: a built-in cell name or a cell file's path, checked by
    name only (the file is read when the cell opens, and its errors come then).

    Raises:
        argparse.ArgumentTypeError: neither a built-in cell nor a cell file.
    """
    import argparse  # here: only the command lines parse arguments

    if value in CELL_NAMES or is_cell_file(value):
        return value
    raise argparse.ArgumentTypeError(
        f"unknown cell {value!r}: expected {', '.join(CELL_NAMES)} or a cell file (*.cell.json)"
    )


def is_cell_file(name: str) -> bool:
    """True when ``name`` names a cell file rather than a built-in cell."""
    return name not in CELL_NAMES and (name.endswith(".json") or Path(name).exists())


def _open_cell_file(
    path: Path, seed: int, scene: str | None, speed: float | None, still_until_run: bool
) -> ClosableCell:
    from capabilities.robot.cell_file import CellConfig, CellConfigError

    try:
        config = CellConfig.load(path)
    except CellConfigError as exc:
        raise CellError(str(exc)) from exc
    if config.robot.kind == "ur":
        try:
            from capabilities.ur.cell import URCellSession

            return URCellSession(config)
        except ImportError as exc:
            raise CellError(f"{path}: the UR cell needs ur_rtde: {exc}") from exc
        except CapabilityError as exc:
            raise CellError(f"{path}: {exc}") from exc
    return _open_sim(seed, scene, speed, still_until_run, config, f"{path}: ")


def _open_sim(
    seed: int,
    scene: str | None,
    speed: float | None,
    still_until_run: bool,
    config: CellConfig | None = None,
    where: str = "",
) -> ClosableCell:
    """The simulated cell (of ``config``, a cell file's, when given); ``where`` starts its
    error messages.
    """
    try:
        from capabilities.sim.session import PERCEPTION_S, SimCellSession
    except ImportError as exc:
        raise CellError(f"the simulated cell cannot load: {exc}") from exc
    try:
        # Always in lockstep, paced or not: each look costs a fixed simulated time while
        # the world stands still and a run's engine drives the world, so what a plan sees
        # does not depend on how busy the machine is.
        return SimCellSession(
            scene or DEFAULT_SCENE,
            seed,
            speed,
            config=config,
            lockstep=PERCEPTION_S,
            still_until_run=still_until_run,
        )
    except Exception as exc:  # scene or model errors: say which, do not crash the CLI/GUI
        raise CellError(f"{where}the simulated cell did not start: {exc}") from exc
