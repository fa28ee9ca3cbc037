"""The node models a BehaviorTree.CPP factory registers for our operations (test helper).

Written from our own manifests (not from the XML under test) in the line format of the
checker program described in tests/engine/test_btcpp_real.py.
"""

from __future__ import annotations

from collections.abc import Iterable

from engine.btcpp.logic import BUILTIN_MODELS, LOGIC
from engine.btcpp.names import encode_id, encode_port
from engine.btcpp.values import MODEL_TYPE, value_text
from engine.kinds import KIND_PORTS
from engine.operations import Direction, OperationKind, OperationManifest, PortSpec
from engine.types import check_value


def _port(port: PortSpec) -> list[str]:
    cpp = MODEL_TYPE[port.type]
    cpp = cpp if cpp in ("double", "bool") else "std::string"  # the rest arrives as text
    direction = "out" if port.direction is Direction.OUT else "in"
    lines = [f"port {direction} {encode_port(port.name)} {cpp}"]
    if port.default is not None and port.direction is Direction.IN:
        fits = [t for t in port.types if check_value(t, port.default)]
        if fits and MODEL_TYPE[fits[0]] == MODEL_TYPE[port.type]:
            lines.append(f"default {value_text(fits[0], port.default)}")
    if port.doc:
        lines.append(f"doc {port.doc}")
    return lines


def models_text(manifests: Iterable[OperationManifest]) -> str:
    """Every operation (and Iterator, Enforce) as "node"/"port"/"default"/"doc" lines."""
    lines: list[str] = []
    for manifest in sorted(manifests, key=lambda m: m.id):
        element = "Condition" if manifest.kind is OperationKind.CONDITION else "Action"
        lines.append(f"node {element} {encode_id(manifest.id, BUILTIN_MODELS)}")
        for port in manifest.ports:
            lines += _port(port)
    for kind, logic in LOGIC.items():
        if not logic.builtin:
            lines.append(f"node {logic.element} {logic.model}")
            for port in KIND_PORTS[kind]:
                lines += _port(port)
    return "\n".join(lines) + "\n"
