"""The capability framework: Omega = <O, gamma, phi> of the paper (section III-A).

A :class:`Capability` is a named group of operations plus the interfaces it requires from
the cell (``arm``, ``gripper``, ``rgbd:wrist``) and the ones it provides. Capabilities are
found through the entry-point group ``costar.capabilities`` (built-in ones exactly like
third-party ones). A :class:`CapabilityRegistry` is an instance made for one cell; it is the
engine's :class:`~engine.operations.OperationSource`.
"""

from __future__ import annotations

import importlib.metadata
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from capabilities.errors import CapabilityError
from engine.operations import (
    Availability,
    Operation,
    OperationManifest,
    OperationNotFound,
    OperationSource,
)

__all__ = [
    "Capability",
    "CapabilityEnv",
    "CapabilityError",
    "CapabilityRegistry",
    "Cell",
    "NullCell",
    "OperationDef",
    "ENTRY_POINT_GROUP",
    "load_entry_point_capabilities",
]

ENTRY_POINT_GROUP = "costar.capabilities"


class Cell(Protocol):
    """A robot cell as capabilities see it: named interfaces and a clock."""

    name: str

    def interfaces(self) -> Mapping[str, Any]:
        """Interface name -> backend object (``"arm"`` -> an arm backend)."""
        ...

    def clock(self) -> float:
        """Seconds; simulated time on the simulated cell."""
        ...


class NullCell:
    """No robot at all: only capabilities that need no interface are available."""

    name = "none"

    def interfaces(self) -> Mapping[str, Any]:
        return {}

    def clock(self) -> float:
        return time.monotonic()


@dataclass(frozen=True)
class CapabilityEnv:
    """What an operation factory gets: the cell, its interfaces and capability settings."""

    cell: Cell
    capability: str
    settings: Mapping[str, Any] = field(default_factory=dict)
    # The registry the operation was made by, for operations that run other operations
    # (timing.wait_until checks a named condition).
    operations: OperationSource | None = None

    def interface(self, name: str) -> Any:
        """The backend behind an interface; raises CapabilityError when the cell lacks it."""
        interfaces = self.cell.interfaces()
        if name not in interfaces:
            raise CapabilityError(f"the {self.cell.name} cell has no {name!r} interface")
        return interfaces[name]


OperationFactoryFn = Callable[[CapabilityEnv], Operation]


@dataclass(frozen=True)
class OperationDef:
    """An operation's manifest and the factory that makes its code for one leaf."""

    manifest: OperationManifest
    factory: OperationFactoryFn


@dataclass
class Capability:
    """A named group of operations and the interfaces they need.

    Attributes:
        name: short id, the prefix of its operation ids (``motion``).
        doc: one line for the palette.
        requires: interfaces the cell must have for the operations to run.
        provides: interfaces this capability offers to others (documentation for now).
        operations: the operations, each with a manifest whose ``capability`` is ``name``.
    """

    name: str
    doc: str
    operations: list[OperationDef] = field(default_factory=list)
    requires: tuple[str, ...] = ()
    provides: tuple[str, ...] = ()

    def add(self, manifest: OperationManifest, factory: OperationFactoryFn) -> None:
        if manifest.capability != self.name:
            raise CapabilityError(
                f"operation {manifest.id!r} says it belongs to {manifest.capability!r}, not {self.name!r}"
            )
        if not manifest.id.startswith(self.name + "."):
            raise CapabilityError(
                f"operation id {manifest.id!r} must start with {self.name + '.'!r}"
            )
        self.operations.append(OperationDef(manifest, factory))


def load_entry_point_capabilities(group: str = ENTRY_POINT_GROUP) -> list[Capability]:
    """Capabilities of every installed package that registers one.

    An entry point names a function that returns a Capability (or a list of them).
    """
    found: list[Capability] = []
    for entry in sorted(importlib.metadata.entry_points(group=group), key=lambda e: e.name):
        try:
            made = entry.load()()
        except Exception as exc:  # a broken plug-in must not take the others down
            raise CapabilityError(
                f"capability entry point {entry.name!r} ({entry.value}) failed: {exc}"
            ) from exc
        items = made if isinstance(made, list) else [made]
        for item in items:
            if not isinstance(item, Capability):
                raise CapabilityError(
                    f"entry point {entry.name!r} returned {type(item).__name__}, not a Capability"
                )
            found.append(item)
    return found


class CapabilityRegistry:
    """The operations available on one cell (an engine OperationSource).

    Args:
        capabilities: what to register (default: every entry point).
        cell: the cell whose interfaces decide what is available.
        settings: per-capability settings, by capability name.
    """

    def __init__(
        self,
        capabilities: Iterable[Capability] | None = None,
        cell: Cell | None = None,
        settings: Mapping[str, Mapping[str, Any]] | None = None,
    ) -> None:
        self.cell: Cell = cell if cell is not None else NullCell()
        self._settings = settings or {}
        self._capabilities: dict[str, Capability] = {}
        self._ops: dict[str, tuple[Capability, OperationDef]] = {}
        self._aliases: dict[str, str] = {}
        for capability in (
            capabilities if capabilities is not None else load_entry_point_capabilities()
        ):
            self.register(capability)

    def register(self, capability: Capability) -> None:
        if capability.name in self._capabilities:
            raise CapabilityError(f"two capabilities are called {capability.name!r}")
        self._capabilities[capability.name] = capability
        for op in capability.operations:
            if op.manifest.id in self._ops:
                raise CapabilityError(f"operation {op.manifest.id!r} is registered twice")
            self._ops[op.manifest.id] = (capability, op)
            for alias in op.manifest.aliases:
                self._aliases[alias] = op.manifest.id

    @property
    def capabilities(self) -> list[Capability]:
        return list(self._capabilities.values())

    def manifests(self) -> list[OperationManifest]:
        return [op.manifest for _, op in self._ops.values()]

    def _lookup(self, op_id: str) -> tuple[Capability, OperationDef]:
        entry = self._ops.get(self._aliases.get(op_id, op_id))
        if entry is None:
            raise OperationNotFound(op_id)
        return entry

    def manifest(self, op_id: str) -> OperationManifest:
        return self._lookup(op_id)[1].manifest

    def capability_availability(self, capability: Capability) -> Availability:
        have = self.cell.interfaces()
        missing = [name for name in capability.requires if name not in have]
        if missing:
            return Availability(
                False,
                f"the {self.cell.name} cell has no {', '.join(missing)} "
                f"(needed by the {capability.name} capability)",
            )
        return Availability()

    def availability(self, op_id: str) -> Availability:
        return self.capability_availability(self._lookup(op_id)[0])

    def create(self, op_id: str) -> Operation:
        capability, op = self._lookup(op_id)
        env = CapabilityEnv(
            self.cell, capability.name, self._settings.get(capability.name, {}), operations=self
        )
        return op.factory(env)

    def aliases(self) -> Mapping[str, str]:
        return dict(self._aliases)
