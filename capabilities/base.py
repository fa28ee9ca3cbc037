"""The capability framework: Omega = <O, gamma, phi> of the paper (section III-A).

A :class:`Capability` is a named group of operations plus the interfaces it requires from
the cell (``arm``, ``gripper``, ``rgbd:wrist``) and the ones it provides. Capabilities are
found through the entry-point group ``costar.capabilities`` (built-in ones exactly like
third-party ones). A :class:`CapabilityRegistry` is an instance made for one cell; it is the
engine's :class:`~engine.operations.OperationSource`.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from capabilities.errors import CapabilityError
from capabilities.kit import CapabilitySettingsError, Setting, parse_settings
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
    "CapabilityLoadError",
    "CapabilityRegistry",
    "Cell",
    "NullCell",
    "SuppliesSettings",
    "OperationClass",
    "OperationDef",
    "ENTRY_POINT_GROUP",
    "load_entry_point_capabilities",
]

ENTRY_POINT_GROUP = "costar.capabilities"


class CapabilityLoadError(CapabilityError):
    """A capability could not be loaded or registered (a broken entry point, a clash)."""


class Cell(Protocol):
    """A robot cell as capabilities see it: named interfaces and a clock."""

    name: str

    def interfaces(self) -> Mapping[str, Any]:
        """Interface name -> backend object (``"arm"`` -> an arm backend)."""
        ...

    def clock(self) -> float:
        """Seconds; simulated time on the simulated cell."""
        ...


@runtime_checkable
class SuppliesSettings(Protocol):
    """A cell whose file gives capability settings (its ``capabilities`` block)."""

    def capability_settings(self) -> tuple[Mapping[str, Any], str]:
        """The ``capabilities`` block (capability name -> settings) and its file, for errors."""
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
    """What ``setup`` and an operation factory get.

    Attributes:
        cell: the cell (its interfaces and clock).
        capability: the capability's name.
        settings: every declared setting, checked, from the cell file or its default.
        operations: the registry that made the operation, for operations that run other
            operations (timing.wait_until checks a named condition).
        state: the capability's per-cell state, made by its ``setup`` hook (None without one).
    """

    cell: Cell
    capability: str
    settings: Mapping[str, Any] = field(default_factory=dict)
    operations: OperationSource | None = None
    state: Any = None

    def interface(self, name: str) -> Any:
        """The backend behind an interface; raises CapabilityError when the cell lacks it."""
        interfaces = self.cell.interfaces()
        if name not in interfaces:
            raise CapabilityError(f"the {self.cell.name} cell has no {name!r} interface")
        return interfaces[name]


class OperationClass(Protocol):
    """An operation's class: its manifest, and made per leaf from the env (``cls(env)``).

    BehaviorTree.CPP's node class with its ``providedPorts()``: the class carries
    ``MANIFEST`` (made with :func:`capabilities.kit.manifest`) and its ``__init__`` takes
    the :class:`CapabilityEnv` (the cell's interfaces, ``env.state``, ``env.settings``).
    """

    MANIFEST: OperationManifest

    def __call__(self, env: CapabilityEnv) -> Operation: ...


@dataclass(frozen=True)
class OperationDef:
    """An operation's manifest and the class that makes its code for one leaf."""

    manifest: OperationManifest
    factory: Callable[[CapabilityEnv], Operation]


@dataclass
class Capability:
    """A named group of operations and the interfaces they need.

    Attributes:
        name: short id, the prefix of its operation ids (``motion``).
        doc: one line for the palette.
        requires: interfaces the cell must have for the operations to run.
        provides: interfaces this capability offers to others (documentation for now).
        operations: the operations (added with :meth:`add`), each with a manifest whose
            ``capability`` is ``name``.
        settings: the settings a cell file may give it (``capabilities.<name>`` block).
        setup: the per-cell hook: called once per registry (one registry per cell) before
            the first operation is made, with the env (cell, checked settings); what it
            returns is ``env.state`` for every operation of this capability on that cell.
    """

    name: str
    doc: str
    operations: list[OperationDef] = field(default_factory=list)
    requires: tuple[str, ...] = ()
    provides: tuple[str, ...] = ()
    settings: tuple[Setting, ...] = ()
    setup: Callable[[CapabilityEnv], Any] | None = None

    def add(self, *operations: OperationClass) -> None:
        """Add operations: each a class with its ``MANIFEST``, made per leaf as ``cls(env)``."""
        for operation in operations:
            manifest = operation.MANIFEST
            if manifest.capability != self.name:
                raise CapabilityLoadError(
                    f"operation {manifest.id!r} says it belongs to {manifest.capability!r}, not {self.name!r}"
                )
            if not manifest.id.startswith(self.name + "."):
                raise CapabilityLoadError(
                    f"operation id {manifest.id!r} must start with {self.name + '.'!r}"
                )
            self.operations.append(OperationDef(manifest, operation))


def load_entry_point_capabilities(group: str = ENTRY_POINT_GROUP) -> list[Capability]:
    """Capabilities of every installed package that registers one.

    An entry point names a function that returns a Capability (or a list of them).
    """
    import importlib.metadata  # here: 70 ms of start-up that commands without a registry skip

    found: list[Capability] = []
    for entry in sorted(importlib.metadata.entry_points(group=group), key=lambda e: e.name):
        try:
            made = entry.load()()
        except Exception as exc:  # a broken plug-in must not take the others down
            raise CapabilityLoadError(
                f"capability entry point {entry.name!r} ({entry.value}) failed: {exc}"
            ) from exc
        items = made if isinstance(made, list) else [made]
        for item in items:
            if not isinstance(item, Capability):
                raise CapabilityLoadError(
                    f"entry point {entry.name!r} returned {type(item).__name__}, not a Capability"
                )
            found.append(item)
    return found


class CapabilityRegistry:
    """The operations available on one cell (an engine OperationSource).

    Args:
        capabilities: what to register (default: every entry point).
        cell: the cell whose interfaces decide what is available.
        settings: the ``capabilities`` block of a cell file (capability name -> its
            settings as JSON values); default: the cell's ``capability_settings()`` when it
            has one. Checked against each capability's declared settings here; a block
            naming no installed capability is an error when ``capabilities`` is None.
        settings_source: the file the settings came from, named in errors.

    Raises:
        CapabilitySettingsError: a settings block names an unknown capability or setting,
            or gives a value of the wrong type.
    """

    def __init__(
        self,
        capabilities: Iterable[Capability] | None = None,
        cell: Cell | None = None,
        settings: Mapping[str, Mapping[str, Any]] | None = None,
        settings_source: str = "the capability settings",
    ) -> None:
        self.cell: Cell = cell if cell is not None else NullCell()
        if settings is None:
            settings, settings_source = _cell_settings(self.cell, settings_source)
        self._raw_settings = settings
        self._settings_source = settings_source
        self._settings: dict[str, dict[str, Any]] = {}
        self._states: dict[str, Any] = {}
        self._lock = threading.Lock()
        self._capabilities: dict[str, Capability] = {}
        self._ops: dict[str, tuple[Capability, OperationDef]] = {}
        self._aliases: dict[str, str] = {}
        for capability in (
            capabilities if capabilities is not None else load_entry_point_capabilities()
        ):
            self.register(capability)
        # A block for a capability this registry lacks is a typo when every installed
        # capability is here; a registry of chosen capabilities skips the others' blocks.
        unknown = sorted(set(settings) - set(self._capabilities))
        if unknown and capabilities is None:
            raise CapabilitySettingsError(
                f"{settings_source}: $.capabilities.{unknown[0]}: no capability of that name "
                f"(capabilities: {', '.join(sorted(self._capabilities))})"
            )

    def register(self, capability: Capability) -> None:
        """Add a capability; its settings are checked against the block given for it."""
        if capability.name in self._capabilities:
            raise CapabilityLoadError(f"two capabilities are called {capability.name!r}")
        self._settings[capability.name] = parse_settings(
            capability.name,
            capability.settings,
            self._raw_settings.get(capability.name, {}),
            self._settings_source,
        )
        self._capabilities[capability.name] = capability
        for op in capability.operations:
            if op.manifest.id in self._ops:
                raise CapabilityLoadError(f"operation {op.manifest.id!r} is registered twice")
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

    def settings(self, capability: str) -> Mapping[str, Any]:
        """The checked settings of a registered capability."""
        return self._settings[capability]

    def create(self, op_id: str) -> Operation:
        capability, op = self._lookup(op_id)
        env = CapabilityEnv(self.cell, capability.name, self._settings[capability.name], self)
        if capability.setup is not None:
            with self._lock:  # setup runs once per cell, even when two threads build trees
                if capability.name not in self._states:
                    self._states[capability.name] = capability.setup(env)
            env = CapabilityEnv(
                env.cell, env.capability, env.settings, self, self._states[capability.name]
            )
        return op.factory(env)

    def aliases(self) -> Mapping[str, str]:
        return dict(self._aliases)


def _cell_settings(cell: Cell, default_source: str) -> tuple[Mapping[str, Any], str]:
    """The cell's capability settings block and the file it came from (none: empty)."""
    if not isinstance(cell, SuppliesSettings):
        return {}, default_source
    return cell.capability_settings()
