"""What a node's input is offered first: the outputs of the nodes before it (issue 26).

A query's output is meant for the nodes after it: when a node's input of type T is bound to
a parameter, the names offered first are those written by outputs of type T of the nodes
that tick before it (depth first, as ``PlanSpec.walk``), the nearest first. Among those, the
outputs of a node that names the same object (an ``object`` value: "pose of CUP" for "grasp
CUP") come before the rest. A fresh node's required input is bound to such an output when
there is exactly one.

No Qt here: the inspector and the window call these with the plan and the cell's operations.
"""

from __future__ import annotations

from dataclasses import replace

from engine.instances import instance_manifest
from engine.operations import Direction, OperationManifest, OperationSource
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType
from instructor_app.node_factory import manifest_or_none

__all__ = ["nodes_before", "nodes_before_insert", "offered_outputs", "prebound"]


def nodes_before(plan: PlanSpec, node_id: str) -> list[NodeSpec]:
    """The nodes that tick before ``node_id`` (depth first), in tick order."""
    before: list[NodeSpec] = []
    for _, node in plan.walk():
        if node.id == node_id:
            return before
        before.append(node)
    return []


def nodes_before_insert(plan: PlanSpec, parent_id: str | None, index: int | None) -> list[NodeSpec]:
    """The nodes that tick before a node inserted under ``parent_id`` at ``index`` (None:
    last), in tick order.
    """
    parent = plan.find(parent_id) if parent_id is not None else None
    if parent is None:
        return []
    children = parent.children[: len(parent.children) if index is None else index]
    if not children:
        return [*nodes_before(plan, parent.id), parent]
    last = children[-1]
    return [*nodes_before(plan, last.id), *(n for _, n in last.walk())]


def _manifest(
    plan: PlanSpec, registry: OperationSource, node: NodeSpec
) -> OperationManifest | None:
    if node.kind is NodeKind.SUBTREE and node.subtree is not None:
        subtree = plan.subtree(node.subtree)
        return instance_manifest(subtree) if subtree is not None else None
    return manifest_or_none(registry, node.op)


def _objects(node: NodeSpec) -> set[str]:
    """The object models a node names by value (its ``object``-typed fixed bindings)."""
    return {
        str(getattr(b.value, "name", b.value))
        for b in node.params.values()
        if not b.is_ref and b.type is ParamType.OBJECT and b.value is not None
    }


def offered_outputs(
    plan: PlanSpec,
    registry: OperationSource,
    before: list[NodeSpec],
    types: tuple[ParamType, ...],
    node: NodeSpec | None = None,
) -> list[str]:
    """Parameter names written by outputs of one of ``types`` of the nodes ``before`` (in tick
    order), the nearest first; those of a node naming one of ``node``'s objects first of all.
    """
    same: list[str] = []
    other: list[str] = []
    objects = _objects(node) if node is not None else set()
    for earlier in reversed(before):
        manifest = _manifest(plan, registry, earlier)
        if manifest is None:
            continue
        shares = bool(objects & _objects(earlier))
        for port in manifest.ports:
            binding = earlier.params.get(port.name)
            if port.direction is not Direction.OUT or binding is None or not binding.ref:
                continue
            if set(port.types) & set(types):
                (same if shares else other).append(binding.ref)
    return list(dict.fromkeys([*same, *other]))


def prebound(
    node: NodeSpec,
    manifest: OperationManifest | None,
    plan: PlanSpec,
    registry: OperationSource,
    before: list[NodeSpec],
) -> NodeSpec:
    """``node`` with each unbound required input bound to the one output of its type written
    before it, when there is exactly one (the node itself when nothing applies).
    """
    if manifest is None:
        return node
    params = dict(node.params)
    for port in manifest.ports:
        if port.direction is not Direction.IN or not port.required or port.name in params:
            continue
        offers = offered_outputs(plan, registry, before, tuple(port.types))
        if len(offers) == 1:
            params[port.name] = Binding.reference(offers[0])
    return node if params == node.params else replace(node, params=params)
