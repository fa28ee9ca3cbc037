"""Operations of the template capability: one manifest and its code per operation."""

from __future__ import annotations

from capabilities.base import Capability
from capabilities.template.backend import INTERFACE, LampBackend
from engine.operations import OperationCall, OperationKind, OperationManifest, PortSpec, StartResult
from engine.types import ParamType

__all__ = ["build_capability", "LAMP_IS_LIT"]

LAMP_IS_LIT = OperationManifest(
    id="template.lamp_is_lit",
    kind=OperationKind.CONDITION,
    doc="True when the stack light shows the given colour.",
    capability="template",
    ports=(
        PortSpec(
            "colour",
            (ParamType.TEXT,),
            default="green",
            doc="which light",
            choices=("green", "amber", "red"),
        ),
    ),
)


class LampIsLit:
    """Reads the lamp through the cell's backend; quick, so it answers at once."""

    def __init__(self, backend: LampBackend) -> None:
        self._backend = backend

    def start(self, call: OperationCall) -> StartResult:
        return self._backend.is_lit(str(call.args["colour"]))


def build_capability() -> Capability:
    cap = Capability("template", "An example to copy.", requires=(INTERFACE,))
    cap.add(LAMP_IS_LIT, lambda env: LampIsLit(env.interface(INTERFACE)))
    return cap
