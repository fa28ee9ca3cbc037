"""The interface this capability needs from a cell (implemented by each cell's backend)."""

from __future__ import annotations

from typing import Protocol

__all__ = ["LampBackend", "INTERFACE"]

INTERFACE = "lamp"


class LampBackend(Protocol):
    """A stack light the cell can read; a real cell reads a digital input."""

    def is_lit(self, colour: str) -> bool: ...
