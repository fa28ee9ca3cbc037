"""Operations of the template capability: each manifest beside the class that runs it.

The one shape of a capability module (copy it):

1. ``CAP`` and, if the capability has per-cell settings, ``SETTINGS`` (typed, with defaults
   and docs; a cell file gives them in its ``capabilities.<CAP>`` block);
2. a per-cell state class and ``setup(env)`` that makes it (py_trees' ``setup()``): what
   the operations of one cell share, made once per cell from the checked settings;
3. per operation: ``NAME = manifest(CAP, ...)`` and, right below it, the class whose
   ``start(call)`` reads typed inputs with ``call.input(port)`` and returns a ``Job``
   (``Job.done()``, ``Job.failed(why)``, ``Job.answer(flag)``, or a running job);
4. ``capability()``: the capability with every operation added, ``env.state`` given to each.
"""

from __future__ import annotations

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import Setting, manifest
from capabilities.template.backend import INTERFACE, LampBackend
from engine.operations import Job, OperationCall, OperationKind, PortSpec
from engine.types import ParamType

__all__ = ["LAMP_IS_LIT", "SETTINGS", "LampState", "capability", "setup"]

CAP = "template"

SETTINGS = (Setting("inverted", bool, False, "true when the lamp's input reads lit as off"),)


class LampState:
    """What the template's operations share on one cell: the backend and the settings."""

    def __init__(self, backend: LampBackend, inverted: bool) -> None:
        self.backend = backend
        self.inverted = inverted

    def is_lit(self, colour: str) -> bool:
        return self.backend.is_lit(colour) != self.inverted


def setup(env: CapabilityEnv) -> LampState:
    """The per-cell hook: the state every template operation of this cell gets."""
    return LampState(env.interface(INTERFACE), env.settings["inverted"])


LAMP_IS_LIT = manifest(
    CAP,
    "lamp_is_lit",
    OperationKind.CONDITION,
    "True when the stack light shows the given colour.",
    PortSpec(
        "colour",
        (ParamType.TEXT,),
        default="green",
        doc="which light",
        choices=("green", "amber", "red"),
    ),
)


class LampIsLit:
    """template.lamp_is_lit: reads the lamp through the cell's backend and answers at once."""

    def __init__(self, state: LampState) -> None:
        self._state = state

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._state.is_lit(call.input("colour")))


def capability() -> Capability:
    """The template capability (requires the ``lamp`` interface)."""
    cap = Capability(
        CAP, "An example to copy.", requires=(INTERFACE,), settings=SETTINGS, setup=setup
    )
    cap.add(LAMP_IS_LIT, lambda env: LampIsLit(env.state))
    return cap
