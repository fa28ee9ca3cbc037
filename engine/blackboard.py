"""The blackboard: one plan's named parameters while it runs (never a global).

Queries write named parameters (the paper's CUP_POSE); other operations read them. Keys may
be declared with a type; a write of another type is refused, so a wrong value is caught
where it is produced rather than where it is used. Each entry remembers who wrote it last
(a node id, "plan" for a start value, :data:`OPERATOR` for a value the user set while the run
was paused), at which tick and when (:meth:`Blackboard.entry`), and how many times it has been
written (its sequence number, BehaviorTree.CPP's ``sequence_id``: :meth:`Blackboard.sequence`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from engine.errors import EngineError
from engine.types import ParamType, check_value

__all__ = ["Blackboard", "BlackboardEntry", "BlackboardError", "MISSING", "OPERATOR"]

OPERATOR = "operator"
"""The writer of a value the user set by hand while the run was paused."""


class BlackboardError(EngineError):
    """A read of a missing entry, or a write of the wrong type."""


class _Missing:
    def __repr__(self) -> str:
        return "MISSING"


MISSING: Any = _Missing()
# get()'s "no default given": apart from MISSING, so that get(key, MISSING) returns MISSING.
_NO_DEFAULT: Any = object()

WriteListener = Callable[[str, Any, str], None]
_now = time.monotonic


def _wrong_type(key: str, ptype: ParamType, value: Any) -> BlackboardError:
    return BlackboardError(
        f"parameter {key!r} holds {ptype.value}, not {type(value).__name__} {value!r}"
    )


@dataclass(frozen=True, slots=True)
class BlackboardEntry:
    """One entry and its last write.

    Attributes:
        key: the blackboard key (inside a subtree instance: ``"label#id6/NAME"``).
        value: its value.
        ptype: its declared type (None: undeclared).
        writer: who wrote it last: a node's runtime id, "plan" (the plan's start value),
            :data:`OPERATOR` (set by the user while paused), "resume".
        tick: the tick it was written at (0: before the first tick).
        time: when (seconds of ``time.monotonic``, as the executor's events).
        sequence: how many times it has been written since it was created (1: once; it
            starts again after an unset, as BehaviorTree.CPP's ``sequence_id``).
    """

    key: str
    value: Any
    ptype: ParamType | None
    writer: str
    tick: int
    time: float
    sequence: int = 0


class Blackboard:
    """Named, optionally typed values of one running tree.

    Written and read on the engine thread; other threads take :meth:`snapshot`.
    """

    def __init__(self, types: Mapping[str, ParamType] | None = None) -> None:
        self._values: dict[str, Any] = {}
        self._types: dict[str, ParamType] = dict(types or {})
        self._listeners: list[WriteListener] = []
        # key -> writer, tick, time, sequence (the number of writes since it was created)
        self._written: dict[str, tuple[str, int, float, int]] = {}
        self._ticks: Callable[[], int] = lambda: 0

    def count_ticks_with(self, ticks: Callable[[], int]) -> None:
        """Stamp each write with ``ticks()`` (the tree's tick count; the tree's context
        sets it).
        """
        self._ticks = ticks

    def declare(self, key: str, ptype: ParamType) -> None:
        """Give a key a type; later writes must match it."""
        self._types[key] = ptype

    def type_of(self, key: str) -> ParamType | None:
        return self._types.get(key)

    def add_write_listener(self, listener: WriteListener) -> None:
        """``listener(key, value, writer_node_id)`` runs after every write."""
        self._listeners.append(listener)

    def check(self, key: str, value: Any) -> None:
        """Raise BlackboardError, naming the entry and its type, when ``value`` does not fit
        ``key``'s declared type (any thread: the types are fixed once the tree is built).
        """
        ptype = self._types.get(key)
        if ptype is not None and not check_value(ptype, value):
            raise _wrong_type(key, ptype, value)

    def set(self, key: str, value: Any, writer: str = "") -> None:
        """Write a value; raises BlackboardError when it does not match the key's type."""
        ptype = self._types.get(key)  # check() inline: a write is on the tick's path
        if ptype is not None and not check_value(ptype, value):
            raise _wrong_type(key, ptype, value)
        self._values[key] = value
        last = self._written.get(key)
        self._written[key] = (writer, self._ticks(), _now(), 1 if last is None else last[3] + 1)
        for listener in self._listeners:
            listener(key, value, writer)

    def get(self, key: str, default: Any = _NO_DEFAULT) -> Any:
        """The value of ``key``; raises BlackboardError when missing and no default is given.

        ``get(key, MISSING)`` returns MISSING for a missing key (a check without a try).
        """
        value = self._values.get(key, default)
        if value is _NO_DEFAULT:
            raise BlackboardError(f"parameter {key!r} has no value yet")
        return value

    def entry(self, key: str) -> BlackboardEntry | None:
        """``key``'s value and its last write (None when it has no value)."""
        value = self._values.get(key, _NO_DEFAULT)
        if value is _NO_DEFAULT:
            return None
        writer, tick, when, sequence = self._written.get(key, ("", 0, 0.0, 0))
        return BlackboardEntry(key, value, self._types.get(key), writer, tick, when, sequence)

    def sequence(self, key: str) -> int:
        """How many times ``key`` has been written since it was created (0: it has no value);
        a node that remembers it can tell whether the entry was written since (BehaviorTree.CPP's
        ``sequence_id``: it starts again when the entry is unset).
        """
        if key not in self._values:
            return 0
        written = self._written.get(key)
        return 0 if written is None else written[3]

    def entries(self) -> list[BlackboardEntry]:
        """Every entry with a value, with its last write (a copy, safe for another thread)."""
        found = (self.entry(key) for key in list(self._values))
        return [entry for entry in found if entry is not None]

    def unset(self, key: str) -> None:
        self._values.pop(key, None)
        self._written.pop(key, None)

    def clear(self) -> None:
        self._values.clear()
        self._written.clear()

    def __contains__(self, key: object) -> bool:
        return key in self._values

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._values))

    def __len__(self) -> int:
        return len(self._values)

    def snapshot(self) -> dict[str, Any]:
        """A copy of all values, safe to hand to another thread."""
        return dict(self._values)
