"""Object symmetries and grasps for smart waypoints, read from the object model library.

This is the one place motion reads the object library (``capabilities.object_library``,
cell-neutral; models are read on first use). Only a model's ``symmetry`` and ``grasps``
blocks are read, never anything about a scene.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from pathlib import Path

from capabilities.object_library import (
    GraspSpec,
    ObjectLibrary,
    ObjectLibraryError,
    Symmetry,
)

__all__ = ["ObjectSymmetry", "SymmetryTable", "NO_SYMMETRY", "object_symmetry"]


@dataclass(frozen=True)
class ObjectSymmetry:
    """Rotations about ``axis`` (object frame) that leave the object looking the same.

    Attributes:
        axis: unit axis in the object frame.
        angles: the equivalent rotation angles (rad), or None for every angle (continuous).
    """

    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    angles: tuple[float, ...] | None = (0.0,)

    @property
    def continuous(self) -> bool:
        return self.angles is None


NO_SYMMETRY = ObjectSymmetry()


class SymmetryTable:
    """The symmetry of each object class, loaded on first use and cached.

    Args:
        library_path: the object library folder (default: the library's own default).
    """

    def __init__(self, library_path: Path | str | None = None) -> None:
        self._path = library_path
        self._library: ObjectLibrary | None = None
        self._cache: dict[str, tuple[ObjectSymmetry, str]] = {}
        self._lock = threading.Lock()

    def lookup(self, object_class: str) -> tuple[ObjectSymmetry, str]:
        """(symmetry, note): NO_SYMMETRY and a note saying why when the model is unknown."""
        with self._lock:
            if object_class not in self._cache:
                self._cache[object_class] = self._load(object_class)
            return self._cache[object_class]

    def grasp(self, object_class: str, name: str = "") -> GraspSpec:
        """The model's grasp ``name`` (empty: its first).

        Raises:
            ObjectLibraryError: no such model or grasp; the message names the choices.
        """
        with self._lock:
            return self._library_now().get(object_class).grasp(name)

    def grasp_names(self) -> tuple[str, ...]:
        """Every grasp name of the library's models, in first-seen order (a broken or
        missing model is left out: using it says what is wrong).
        """
        names: dict[str, None] = {}
        with self._lock:
            library = self._library_now()
            try:
                models = library.names()
            except OSError:
                return ()
            for model in models:
                try:
                    names.update(dict.fromkeys(g.name for g in library.get(model).grasps))
                except (ObjectLibraryError, OSError):
                    continue
        return tuple(names)

    def _library_now(self) -> ObjectLibrary:
        if self._library is None:
            self._library = ObjectLibrary(self._path)
        return self._library

    def _load(self, object_class: str) -> tuple[ObjectSymmetry, str]:
        try:
            symmetry = self._library_now().get(object_class).symmetry
        except (ObjectLibraryError, OSError) as exc:
            return NO_SYMMETRY, f"no symmetry used for {object_class!r}: {exc}"
        return object_symmetry(symmetry), ""


def object_symmetry(symmetry: Symmetry) -> ObjectSymmetry:
    """A model's symmetry block as the equivalent rotations motion turns a tool pose by."""
    if symmetry.kind == "continuous":
        return ObjectSymmetry(_unit(symmetry.axis), None)
    if symmetry.kind == "discrete":
        order = max(1, int(symmetry.order))
        angles = tuple(2 * math.pi * k / order for k in range(order))
        return ObjectSymmetry(_unit(symmetry.axis), angles)
    return NO_SYMMETRY


def _unit(axis: tuple[float, ...]) -> tuple[float, float, float]:
    norm = math.sqrt(sum(v * v for v in axis))
    if norm < 1e-9:
        return (0.0, 0.0, 1.0)
    return (axis[0] / norm, axis[1] / norm, axis[2] / norm)
