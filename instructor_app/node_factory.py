"""What the palette offers and the nodes it makes, computed from the registry alone.

Logic kinds come from :mod:`engine.spec` / :mod:`engine.kinds`, operations from the
registry's manifests; a capability package that registers new operations appears in the
palette without a change here. No Qt: the canvas and the palette share this module.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from engine.kinds import KIND_DOC, KIND_PORTS, setting
from engine.operations import OperationKind, OperationManifest, OperationNotFound, OperationSource
from engine.spec import KIND_CATEGORY, Category, NodeKind, NodeSpec
from instructor_app.errors import InstructorError

__all__ = [
    "PALETTE_MIME",
    "PICK_SUBTREE",
    "LOGIC_GROUPS",
    "NodeFactoryError",
    "PaletteItem",
    "palette_items",
    "make_node",
    "make_node_for",
    "item_from_payload",
    "item_from_mime",
    "readable",
    "manifest_or_none",
    "pick_payload",
]

PALETTE_MIME = "application/x-costar-palette-item"
# The shipped Pick subtree (resources/library/pick_place): an object model dragged onto the
# canvas becomes an instance of it with the object as its input ("Pick cup").
PICK_SUBTREE = "pick_place.pick"

# Group titles of the logic kinds, in the order the palette shows them.
LOGIC_GROUPS: dict[Category, str] = {
    Category.COMPOSITE: "Composites",
    Category.DECORATOR: "Decorators",
    Category.LEAF: "Leaves",
}

# Values a fresh node's required ports start with (optional ones use the manifest's default).
_START_VALUES: dict[NodeKind, float] = {
    NodeKind.REPEAT: 2,
    NodeKind.RETRY: 2,
    NodeKind.TIMEOUT: 5.0,
    NodeKind.WAIT: 1.0,
    NodeKind.DELAY: 1.0,
}


class NodeFactoryError(InstructorError):
    """A palette item or dropped payload that names no known kind or operation."""


@dataclass(frozen=True)
class PaletteItem:
    """One entry of the palette.

    Attributes:
        kind: the node kind it makes.
        op: the operation id, for kind OPERATION.
        label: what the palette shows ("Sequence", "Move to").
        doc: one line, shown as tooltip and in the inspector.
        group: the section it is listed under (a logic category or a capability name).
        available: whether it can be inserted on this cell.
        reason: why not, when unavailable.
        op_kind: action, query or condition, for operations (its colour).
    """

    kind: NodeKind
    op: str | None
    label: str
    doc: str
    group: str
    available: bool = True
    reason: str = ""
    op_kind: OperationKind | None = None

    @property
    def payload(self) -> dict[str, Any]:
        """The drag data: ``{"kind": ..., "op": ...}``."""
        return {"kind": self.kind.value, "op": self.op}

    def matches(self, text: str) -> bool:
        """Whether a search text finds this item (every word in label, id, group or doc)."""
        haystack = " ".join((self.label, self.op or self.kind.value, self.group, self.doc)).lower()
        return all(word in haystack for word in text.lower().split())


def readable(identifier: str) -> str:
    """``motion.move_to`` -> ``Move to``; ``reactive_sequence`` -> ``Reactive sequence``."""
    text = identifier.rsplit(".", 1)[-1].replace("_", " ").strip()
    return text[:1].upper() + text[1:]


def _logic_items() -> list[PaletteItem]:
    items = []
    for category, title in LOGIC_GROUPS.items():
        for kind in NodeKind:
            if kind in (NodeKind.OPERATION, NodeKind.SUBTREE):
                continue  # operations come by capability, subtree instances from the library
            if KIND_CATEGORY[kind] is not category:
                continue
            items.append(
                PaletteItem(kind, None, readable(kind.value), KIND_DOC.get(kind, ""), title)
            )
    return items


def palette_items(registry: OperationSource) -> list[PaletteItem]:
    """Logic kinds, then every operation of the registry grouped by capability (sorted)."""
    items = _logic_items()
    manifests = sorted(registry.manifests(), key=lambda m: (m.capability, m.id))
    for manifest in manifests:
        availability = registry.availability(manifest.id)
        items.append(
            PaletteItem(
                NodeKind.OPERATION,
                manifest.id,
                readable(manifest.id),
                manifest.doc,
                manifest.capability,
                availability.available,
                availability.reason,
                manifest.kind,
            )
        )
    return items


def make_node(item: PaletteItem, manifest: OperationManifest | None = None) -> NodeSpec:
    """A fresh node (new uuid) for a palette item.

    Required settings of logic kinds start with usable values (Repeat 2 times, Timeout 5 s,
    Wait 1 s). Operation ports stay unbound: their defaults apply when the tree is built,
    and validation lists the ones that need a value.
    """
    if item.kind is NodeKind.OPERATION:
        if not item.op:
            raise NodeFactoryError(f"palette item {item.label!r} names no operation")
        name = readable(manifest.id if manifest is not None else item.op)
        return NodeSpec(NodeKind.OPERATION, name=name, op=item.op)
    params = {
        port.name: setting(item.kind, port.name, _START_VALUES[item.kind])
        for port in KIND_PORTS.get(item.kind, ())
        if port.required and item.kind in _START_VALUES
    }
    return NodeSpec(item.kind, name=item.label, params=params)


def pick_payload(object_name: str) -> dict[str, Any]:
    """The drag data of an object model: a Pick of that object (``"object"`` names it; the
    library binds it to the subtree's first object input).
    """
    return {"kind": NodeKind.SUBTREE.value, "op": PICK_SUBTREE, "object": object_name}


def item_from_payload(payload: Any, registry: OperationSource) -> PaletteItem:
    """The palette item a drag payload names (checked against the registry)."""
    if not isinstance(payload, dict):
        raise NodeFactoryError(f"a palette payload is an object, not {payload!r}")
    try:
        kind = NodeKind(payload.get("kind"))
    except ValueError as exc:
        raise NodeFactoryError(f"no node kind {payload.get('kind')!r}") from exc
    op = payload.get("op")
    for item in palette_items(registry):
        if item.kind is kind and item.op == (op if kind is NodeKind.OPERATION else None):
            return item
    raise NodeFactoryError(f"the cell has no operation {op!r}")


def item_from_mime(data: bytes, registry: OperationSource) -> PaletteItem:
    """The palette item of :data:`PALETTE_MIME` bytes (what the palette drags)."""
    try:
        payload = json.loads(bytes(data).decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise NodeFactoryError(f"palette data is not JSON: {exc}") from exc
    return item_from_payload(payload, registry)


def make_node_for(kind: NodeKind | str, op: str | None, registry: OperationSource) -> NodeSpec:
    """A fresh node for a kind and operation id (a drop's payload, "Add child" menus)."""
    value = kind.value if isinstance(kind, NodeKind) else kind
    item = item_from_payload({"kind": value, "op": op}, registry)
    return make_node(item, manifest_or_none(registry, item.op))


def manifest_or_none(registry: OperationSource, op: str | None) -> OperationManifest | None:
    """The manifest of ``op``, None when there is no such operation."""
    if not op:
        return None
    try:
        return registry.manifest(op)
    except OperationNotFound:
        return None
