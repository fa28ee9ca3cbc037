"""The blackboard: one plan's named parameters while it runs (never a global).

Queries write named parameters (the paper's CUP_POSE); other operations read them. Keys may
be declared with a type; a write of another type is refused, so a wrong value is caught
where it is produced rather than where it is used.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from typing import Any

from engine.errors import EngineError
from engine.types import ParamType, check_value

__all__ = ["Blackboard", "BlackboardError", "MISSING"]


class BlackboardError(EngineError):
    """A read of a missing entry, or a write of the wrong type."""


class _Missing:
    def __repr__(self) -> str:
        return "MISSING"


MISSING: Any = _Missing()
# get()'s "no default given": apart from MISSING, so that get(key, MISSING) returns MISSING.
_NO_DEFAULT: Any = object()

WriteListener = Callable[[str, Any, str], None]


class Blackboard:
    """Named, optionally typed values of one running tree.

    Written and read on the engine thread; other threads take :meth:`snapshot`.
    """

    def __init__(self, types: Mapping[str, ParamType] | None = None) -> None:
        self._values: dict[str, Any] = {}
        self._types: dict[str, ParamType] = dict(types or {})
        self._listeners: list[WriteListener] = []

    def declare(self, key: str, ptype: ParamType) -> None:
        """Give a key a type; later writes must match it."""
        self._types[key] = ptype

    def type_of(self, key: str) -> ParamType | None:
        return self._types.get(key)

    def add_write_listener(self, listener: WriteListener) -> None:
        """``listener(key, value, writer_node_id)`` runs after every write."""
        self._listeners.append(listener)

    def set(self, key: str, value: Any, writer: str = "") -> None:
        """Write a value; raises BlackboardError when it does not match the key's type."""
        ptype = self._types.get(key)
        if ptype is not None and not check_value(ptype, value):
            raise BlackboardError(
                f"parameter {key!r} holds {ptype.value}, not {type(value).__name__} {value!r}"
            )
        self._values[key] = value
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

    def unset(self, key: str) -> None:
        self._values.pop(key, None)

    def clear(self) -> None:
        self._values.clear()

    def __contains__(self, key: object) -> bool:
        return key in self._values

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._values))

    def __len__(self) -> int:
        return len(self._values)

    def snapshot(self) -> dict[str, Any]:
        """A copy of all values, safe to hand to another thread."""
        return dict(self._values)
