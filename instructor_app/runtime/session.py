"""Which cell the Instructor works with, and the capability registry made for it."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Signal

from capabilities.base import CapabilityRegistry
from capabilities.cells import CELL_NAMES, CellError, open_cell

__all__ = ["CellSession", "CellOpener", "RegistryFactory"]

CellOpener = Callable[..., Any]
RegistryFactory = Callable[[Any], CapabilityRegistry]


def _default_registry(cell: Any) -> CapabilityRegistry:
    return CapabilityRegistry(cell=cell)


class CellSession(QObject):
    """The cell in use ("sim" or "none") and its registry.

    Opening is synchronous: the simulated cell starts in about half a second, which the
    window accepts at start-up and on a switch; nothing longer happens here.

    Args:
        name: the cell to open first (nothing is opened until :meth:`open`).
        seed: scene seed of the simulated cell.
        speed: real-time factor of the simulated cell (1.0 real time; None as fast as
            possible).
        scene: scene of the simulated cell (default: the cell's default).
        opener: opens a cell by name (tests may inject a fake).
        registry_factory: makes the registry for an open cell.

    Signals:
        cell_changed(str): a cell was opened (its name).
        registry_changed(object): the new CapabilityRegistry; panels rebuild from it.
        cell_failed(str): a cell could not be opened (the message); "none" is used instead.
    """

    cell_changed = Signal(str)
    registry_changed = Signal(object)
    cell_failed = Signal(str)

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
        self.scene = scene
        self._opener = opener
        self._registry_factory = registry_factory
        self.cell: Any = None
        self.registry: CapabilityRegistry = registry_factory(None)

    @staticmethod
    def cell_names() -> tuple[str, ...]:
        return CELL_NAMES

    def open(self, name: str | None = None) -> bool:
        """Close the current cell and open ``name`` (default: the one given at creation).

        Returns False when the cell failed to open; then the "none" cell is in use and
        ``cell_failed`` said why.
        """
        wanted = name or self.name
        self.close()
        ok = True
        try:
            self.cell = self._opener(wanted, seed=self.seed, scene=self.scene, speed=self.speed)
        except CellError as exc:
            ok = False
            self.cell_failed.emit(str(exc))
            wanted = "none"
            self.cell = self._opener("none", seed=self.seed)
        self.name = wanted
        self.registry = self._registry_factory(self.cell)
        self.cell_changed.emit(wanted)
        self.registry_changed.emit(self.registry)
        return ok

    def reset(self) -> bool:
        """Put the cell back to its start: the same cell opened again with the same scene
        and seed (robot at home, objects where the seed places them) and a fresh registry,
        so that no capability keeps state of an earlier run. Returns as :meth:`open`."""
        return self.open(self.name)

    def clock(self) -> Callable[[], float] | None:
        """The open cell's clock (simulated time on the simulated cell), None if none open."""
        return self.cell.clock if self.cell is not None else None

    def close(self) -> None:
        """Release the open cell (its threads); safe to call twice."""
        cell, self.cell = self.cell, None
        if cell is not None:
            cell.close()
