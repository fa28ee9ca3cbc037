"""The capability kit: the one way to declare a capability's operations and settings.

A capability module declares each operation as a class that carries its manifest (made
with :func:`manifest`) as ``MANIFEST``, as a BehaviorTree.CPP node class carries its
``providedPorts()``, and one function ``capability() -> Capability`` adds the classes. The
registry makes one instance per leaf as ``cls(env)``. Per-cell state and settings come
through one hook, as py_trees' ``setup()``: a capability declares its settings as
:class:`Setting` fields (typed, with defaults and docs) and a ``setup`` function that makes
its per-cell state object from them; the registry calls ``setup`` once per cell, and every
operation finds that object as ``env.state`` and the checked settings as ``env.settings``. The cell file supplies the settings in its ``capabilities``
block; an unknown key or a wrong type is a :class:`CapabilitySettingsError` naming the file
and the key, and an explicit 0 is 0.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar, cast

from capabilities.errors import CapabilityError
from engine.operations import (
    Direction,
    InPort,
    OperationFailed,
    OperationKind,
    OperationManifest,
    PortRule,
    PortSpec,
    duration,
    flag,
    joints,
    number,
    object_model,
    pose,
    region,
    text,
)
from engine.types import ParamType, Pose, ValueShapeError, decode_value

if TYPE_CHECKING:
    from capabilities.base import CapabilityEnv, OperationClass

# The declaration side of engine.operations, so that an operation module takes what its
# manifests are made of from here: the kinds and the typed input ports.
__all__ = [
    "CAMERAS",
    "InPort",
    "OperationKind",
    "duration",
    "flag",
    "joints",
    "number",
    "object_model",
    "pose",
    "region",
    "text",
    "camera_port",
    "CapabilitySettingsError",
    "Setting",
    "StatefulOperation",
    "camera",
    "manifest",
    "output",
    "parse_settings",
    "variant",
]

CAMERAS = ("shoulder", "wrist")
"""The RGB-D cameras a cell may have (the choices of a ``camera`` port)."""


def camera_port(doc: str = "which camera looks") -> InPort[str]:
    """The ``camera`` input of an operation that looks through one (default: shoulder)."""
    return text("camera", "shoulder", doc=doc, choices=CAMERAS)


def camera(env: CapabilityEnv, name: str) -> Any:
    """The RGB-D camera ``name`` of the cell (its interface ``rgbd:<name>``).

    Raises:
        OperationFailed: the cell has no such camera.
    """
    found = env.cell.interfaces().get(f"rgbd:{name}")
    if found is None:
        raise OperationFailed(f"the {env.cell.name} cell has no {name} camera")
    return found


class CapabilitySettingsError(CapabilityError):
    """A cell file's ``capabilities`` block has an unknown key or a value of the wrong type."""


def manifest(
    capability: str,
    name: str,
    kind: OperationKind,
    doc: str,
    *ports: PortSpec,
    aliases: tuple[str, ...] = (),
    rules: tuple[PortRule, ...] = (),
) -> OperationManifest:
    """The manifest of operation ``capability.name`` (the one manifest helper).

    ``rules`` are checks across its ports (:data:`engine.operations.PortRule`): an input
    that another input's type or value makes meaningless is a validation error, never
    accepted and then ignored.

    Example::

        COLOUR = text("colour", "green", doc="which light")

        class LampIsLit:
            MANIFEST = manifest("template", "lamp_is_lit", OperationKind.CONDITION,
                                "True when the stack light shows the given colour.", COLOUR)
    """
    return OperationManifest(
        f"{capability}.{name}", kind, doc, capability, ports, aliases, rules=rules
    )


def output(name: str, *types: ParamType, unit: str = "", doc: str = "") -> PortSpec:
    """The output port ``name`` of a manifest: the entry the operation writes (``call.write``).

    Example: ``output("pose", ParamType.POSE, doc="where the object is")``.
    """
    return PortSpec(name, types, Direction.OUT, unit=unit, doc=doc)


S = TypeVar("S")


class StatefulOperation(Generic[S]):
    """An operation over its capability's per-cell state: ``self._state`` is ``env.state``.

    The type parameter is the state's class (what the capability's ``setup`` returns):
    ``class _Op(StatefulOperation[LampState])`` gives ``self._state`` that type; a state
    class imported only for type checking is named as a string.
    """

    def __init__(self, env: CapabilityEnv) -> None:
        self._state: S = env.state


def variant(base: type, manifest: OperationManifest, **values: Any) -> OperationClass:
    """The class of one operation of a family that differs only in values.

    A subclass of ``base`` with ``MANIFEST`` and the class attributes in ``values``, named
    after the operation: ``variant(_Relation, _relation_manifest("left_of"),
    RELATION="left_of")`` is ``LeftOf``, documented as ``predicates.left_of``.
    """
    words = manifest.id.split(".", 1)[1].split("_")
    attributes = {"MANIFEST": manifest, "__doc__": f"{manifest.id}.", "__module__": base.__module__}
    made = type("".join(w.title() for w in words), (base,), {**attributes, **values})
    return cast("OperationClass", made)


_PY_TYPES: dict[type, str] = {
    float: "a number",
    int: "an integer",
    bool: "true or false",
    str: "a text",
    Pose: "a pose",
}


@dataclass(frozen=True)
class Setting:
    """One per-cell setting of a capability, as the cell file's ``capabilities`` block gives it.

    Attributes:
        name: the key in the block.
        type: float (SI units; an integer is taken as a float), int, bool, str, Pose
            (the JSON form of a Pose parameter) or tuple (a list of ``size`` numbers,
            read as a tuple of floats).
        default: the value when the cell file does not give one (None: not set).
        doc: one line saying what it does and its unit.
        size: how many numbers a tuple setting has.
    """

    name: str
    type: type
    default: Any = None
    doc: str = ""
    size: int = 0

    def parse(self, value: Any, where: str) -> Any:
        """The setting's value from its JSON form; raises CapabilitySettingsError."""
        if value is None:
            return None
        if self.type is Pose and isinstance(value, Pose):  # given in code, not from a file
            return value
        if self.type is Pose:
            try:
                return decode_value(ParamType.POSE, value, where)
            except ValueShapeError as exc:
                raise CapabilitySettingsError(str(exc)) from exc
        if self.type is tuple:
            return self._numbers(value, where)
        ok = isinstance(value, self.type) and not (
            self.type is not bool and isinstance(value, bool)
        )
        if self.type is float and isinstance(value, int) and not isinstance(value, bool):
            return float(value)
        if not ok:
            expected = _PY_TYPES.get(self.type, self.type.__name__)
            raise CapabilitySettingsError(f"{where}: expected {expected}, got {value!r}")
        return value

    def _numbers(self, value: Any, where: str) -> tuple[float, ...]:
        if (
            not isinstance(value, (list, tuple))
            or len(value) != self.size
            or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)
        ):
            raise CapabilitySettingsError(
                f"{where}: expected a list of {self.size} numbers, got {value!r}"
            )
        return tuple(float(v) for v in value)


def parse_settings(
    capability: str, schema: tuple[Setting, ...], raw: Mapping[str, Any], source: str
) -> dict[str, Any]:
    """A capability's settings: every schema field, from ``raw`` or its default.

    Args:
        capability: the capability's name (the key of its block).
        schema: the capability's declared settings.
        raw: the block from the cell file (JSON values).
        source: the file the block came from, for error messages.

    Raises:
        CapabilitySettingsError: an unknown key or a wrong type, naming the file and key.
    """
    if not isinstance(raw, Mapping):
        raise CapabilitySettingsError(
            f"{source}: $.capabilities.{capability}: expected an object, got {raw!r}"
        )
    fields = {s.name: s for s in schema}
    for key in raw:
        if key not in fields:
            known = ", ".join(fields) or "none"
            raise CapabilitySettingsError(
                f"{source}: $.capabilities.{capability}.{key}: unknown setting "
                f"(the {capability} capability has: {known})"
            )
    values: dict[str, Any] = {}
    for setting in schema:
        where = f"{source}: $.capabilities.{capability}.{setting.name}"
        values[setting.name] = (
            setting.parse(raw[setting.name], where) if setting.name in raw else setting.default
        )
    return values
