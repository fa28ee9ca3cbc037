"""Palette items and fresh nodes come from the registry alone."""

from __future__ import annotations

import json

import pytest

from capabilities.base import Capability, CapabilityRegistry, NullCell
from engine.kinds import settings_of
from engine.operations import OperationKind, OperationManifest
from engine.spec import Binding, NodeKind
from engine.types import ParamType
from instructor_app.node_factory import (
    NodeFactoryError,
    PaletteItem,
    item_from_mime,
    item_from_payload,
    make_node,
    make_node_for,
    palette_items,
    readable,
)


def _item(registry: CapabilityRegistry, kind: NodeKind, op: str | None = None) -> PaletteItem:
    return next(i for i in palette_items(registry) if i.kind is kind and i.op == op)


def test_every_logic_kind_and_operation_is_an_item(registry: CapabilityRegistry) -> None:
    items = palette_items(registry)
    kinds = {i.kind for i in items if i.op is None}
    # subtree instances come from the library (library_wiring.library_palette_items)
    assert kinds == set(NodeKind) - {NodeKind.OPERATION, NodeKind.SUBTREE}
    ops = {i.op for i in items if i.op is not None}
    assert ops == {m.id for m in registry.manifests()}


def test_unavailable_operation_carries_the_reason(registry: CapabilityRegistry) -> None:
    lamp = _item(registry, NodeKind.OPERATION, "template.lamp_is_lit")
    assert not lamp.available
    assert "lamp" in lamp.reason
    assert lamp.op_kind is OperationKind.CONDITION
    assert _item(registry, NodeKind.OPERATION, "debug.succeed").available


def test_a_new_capability_appears_without_gui_changes() -> None:
    cap = Capability("welding", "Welds.")

    class WeldSeam:  # a stand-in operation: the palette reads only its manifest
        MANIFEST = OperationManifest("welding.weld_seam", OperationKind.ACTION, "Welds.", "welding")

        def __init__(self, env: object) -> None:
            pass

    cap.add(WeldSeam)  # type: ignore[arg-type]  # no start(): never run
    items = palette_items(CapabilityRegistry([cap], cell=NullCell()))
    weld = [i for i in items if i.op == "welding.weld_seam"]
    assert len(weld) == 1 and weld[0].group == "welding" and weld[0].label == "Weld seam"


@pytest.mark.parametrize(
    ("kind", "config"),
    [
        (NodeKind.REPEAT, {"count": 2}),
        (NodeKind.RETRY, {"count": 2}),
        (NodeKind.TIMEOUT, {"seconds": 5.0}),
        (NodeKind.WAIT, {"seconds": 1.0}),
        (NodeKind.DELAY, {"seconds": 1.0}),
        (NodeKind.TRY_CATCH, {}),
        (NodeKind.RUN_ONCE, {}),
        (NodeKind.PARALLEL, {}),
        (NodeKind.SEQUENCE, {}),
    ],
)
def test_logic_nodes_start_with_valid_settings(
    registry: CapabilityRegistry, kind: NodeKind, config: dict[str, object]
) -> None:
    node = make_node(_item(registry, kind))
    assert node.kind is kind
    assert {k: b.value for k, b in node.params.items()} == config
    settings_of(kind, node.params)  # raises when a start value does not fit


def test_operation_node_has_fresh_id_readable_name_and_no_bindings(
    registry: CapabilityRegistry,
) -> None:
    item = _item(registry, NodeKind.OPERATION, "debug.pretend_move")
    a, b = make_node(item, registry.manifest("debug.pretend_move")), make_node(item)
    assert a.id != b.id
    assert a.op == "debug.pretend_move" and a.name == "Pretend move" and a.params == {}


def test_payload_round_trip(registry: CapabilityRegistry) -> None:
    item = _item(registry, NodeKind.OPERATION, "debug.query")
    data = json.dumps(item.payload).encode()
    assert item_from_mime(data, registry) == item
    assert item_from_payload({"kind": "retry", "op": None}, registry).kind is NodeKind.RETRY
    with pytest.raises(NodeFactoryError):
        item_from_payload({"kind": "operation", "op": "nope.nothing"}, registry)
    with pytest.raises(NodeFactoryError):
        item_from_mime(b"{not json", registry)


def test_make_node_needs_an_operation_id() -> None:
    with pytest.raises(NodeFactoryError):
        make_node(PaletteItem(NodeKind.OPERATION, None, "x", "", "g"))


def test_readable_names() -> None:
    assert readable("motion.move_to") == "Move to"
    assert readable("reactive_sequence") == "Reactive sequence"


def test_search_matches_every_word(registry: CapabilityRegistry) -> None:
    item = _item(registry, NodeKind.OPERATION, "debug.pretend_move")
    assert item.matches("pretend") and item.matches("DEBUG move") and not item.matches("lamp")


def test_make_node_for_kind_and_op(registry: CapabilityRegistry) -> None:
    node = make_node_for(NodeKind.OPERATION, "debug.query", registry)
    assert node.op == "debug.query" and node.name == "Query"
    assert make_node_for("timeout", None, registry).params == {
        "seconds": Binding.fixed(5.0, ParamType.DURATION)
    }
    with pytest.raises(NodeFactoryError):
        make_node_for("no_such_kind", None, registry)
