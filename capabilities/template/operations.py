"""Operations of the template capability: each manifest beside the class that runs it.

The one shape of a capability module (copy it):

1. ``CAP`` and, if the capability has per-cell settings, ``SETTINGS`` (typed, with defaults
   and docs; a cell file gives them in its ``capabilities.<CAP>`` block);
2. a per-cell state class and ``setup(env)`` that makes it (py_trees' ``setup()``): what
   the operations of one cell share, made once per cell from the checked settings;
3. its input ports, made with the typed constructors :mod:`capabilities.kit` re-exports
   (``text``, ``number``, ``duration``, ``flag``, ``pose``...), output ports with
   ``output``;
4. per operation, one class: ``MANIFEST = manifest(CAP, ...)`` listing its ports,
   ``__init__(env)`` (the registry makes one per leaf; ``env.state`` is what ``setup``
   made, kept as ``self._state`` by the base ``StatefulOperation[LampState]``) and
   ``start(call)``, which reads each input through its port (``call.input(COLOUR)``
   is a ``str``) and returns a ``Job`` (``Job.done()``, ``Job.failed(why)``,
   ``Job.answer(flag)``, or a running job);
5. ``capability()``: the capability with every operation class added.
"""

from __future__ import annotations

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import OperationKind, Setting, StatefulOperation, manifest, text
from capabilities.template.backend import INTERFACE, LampBackend
from engine.operations import Job, OperationCall

__all__ = ["COLOUR", "SETTINGS", "LampIsLit", "LampState", "capability", "setup"]

CAP = "template"

SETTINGS = (Setting("inverted", bool, False, "true when the lamp's input reads lit as off"),)


class LampState:
    """What the template's operations share on one cell: the backend and the settings."""

    def __init__(self, backend: LampBackend, inverted: bool) -> None:
        self.backend = backend
        self.inverted = inverted

    def is_lit(self, colour: str) -> bool:
        """Whether the light of ``colour`` is lit (the setting ``inverted`` applied)."""
        return self.backend.is_lit(colour) != self.inverted


def setup(env: CapabilityEnv) -> LampState:
    """The per-cell hook: the state every template operation of this cell gets."""
    return LampState(env.interface(INTERFACE), env.settings["inverted"])


COLOUR = text("colour", "green", doc="which light", choices=("green", "amber", "red"))


class LampIsLit(StatefulOperation[LampState]):
    """template.lamp_is_lit: reads the lamp through the cell's backend and answers at once."""

    MANIFEST = manifest(
        CAP,
        "lamp_is_lit",
        OperationKind.CONDITION,
        "True when the stack light shows the given colour.",
        COLOUR,
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._state.is_lit(call.input(COLOUR)))


def capability() -> Capability:
    """The template capability (requires the ``lamp`` interface)."""
    cap = Capability(
        CAP, "An example to copy.", requires=(INTERFACE,), settings=SETTINGS, setup=setup
    )
    cap.add(LampIsLit)
    return cap
