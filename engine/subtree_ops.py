"""Edits between plain nodes and subtree instances, on specs (the document wraps them in undo).

- :func:`make_subtree`: a subtree from a node of a plan, with chosen parameters left open
  (declared inputs) and chosen names its queries write declared as outputs; names read from
  outside become inputs too, so that the subtree is complete.
- :func:`instance_of`: the instance that does what the original nodes did (open inputs bound
  to the values they had, outside names bound to themselves).
- :func:`detach`: an instance turned back into plain nodes, its inputs and outputs written
  into the nodes and its private names renamed where the plan already uses them.
- :func:`update`: an instance moved to another version of its subtree, keeping the bindings
  of the ports that still exist.
- :func:`find_usages`: the instances of a subtree in the plan files of a folder.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from engine.instances import instance_manifest
from engine.json_reader import JsonFileError
from engine.kinds import KIND_PORTS
from engine.operations import Direction, OperationNotFound, OperationSource, PortSpec
from engine.plan_format import PLAN_SUFFIX
from engine.plan_reader import load_plan
from engine.spec import (
    Binding,
    NodeKind,
    NodeSpec,
    PlanSpec,
    SubtreePort,
    SubtreeRef,
    SubtreeSpec,
    new_id,
)
from engine.types import ParamType

__all__ = [
    "OpenPort",
    "PortsOf",
    "Usage",
    "detach",
    "find_usages",
    "instance_name",
    "ports_bound_elsewhere",
    "instance_of",
    "make_subtree",
    "names_used",
    "ports_of",
    "subtrees_in_use",
    "update",
]

# A node's ports: its operation's manifest, its kind's ports, or its subtree's.
PortsOf = Callable[[NodeSpec], Sequence[PortSpec]]


@dataclass(frozen=True)
class OpenPort:
    """A parameter left open: ``port`` of node ``node_id`` becomes the input ``name``."""

    node_id: str
    port: str
    name: str
    doc: str = ""


def ports_of(plan: PlanSpec, source: OperationSource) -> PortsOf:
    """The ports of the nodes of ``plan``: operations' manifests, kinds' ports, instances'."""

    def ports(node: NodeSpec) -> Sequence[PortSpec]:
        if node.kind is NodeKind.OPERATION and node.op:
            try:
                return source.manifest(node.op).ports
            except OperationNotFound:
                return ()
        if node.kind is NodeKind.SUBTREE and node.subtree is not None:
            subtree = plan.subtree(node.subtree)
            return instance_manifest(subtree).ports if subtree is not None else ()
        return KIND_PORTS.get(node.kind, ())

    return ports


def _fresh(node: NodeSpec) -> NodeSpec:
    clone = copy.deepcopy(node)
    for _, inner in clone.walk():
        inner.id = new_id()
    return clone


def _one_type(port: PortSpec) -> ParamType:
    """The type of a name a port reads or writes: its one type, or Any when it takes several."""
    return port.types[0] if len(port.types) == 1 else ParamType.ANY


def _reads_and_writes(
    root: NodeSpec, ports_of: PortsOf
) -> tuple[dict[str, ParamType], dict[str, ParamType]]:
    """Names read and written by references below ``root``, with their ports' types."""
    reads: dict[str, ParamType] = {}
    writes: dict[str, ParamType] = {}
    for _, node in root.walk():
        by_name = {p.name: p for p in ports_of(node)}
        for port_name, binding in node.params.items():
            port = by_name.get(port_name)
            if binding.ref is None or port is None:
                continue
            target = writes if port.direction is Direction.OUT else reads
            target.setdefault(binding.ref, _one_type(port))
    return reads, writes


def make_subtree(
    root: NodeSpec,
    name: str,
    ports_of: PortsOf,
    open_ports: Sequence[OpenPort] = (),
    outputs: Mapping[str, str] | None = None,
    description: str = "",
) -> SubtreeSpec:
    """A subtree (version 0: not saved yet) made from ``root`` and the nodes below it.

    Args:
        root: the node the subtree starts at (copied with new ids; not changed).
        name: the subtree's name.
        ports_of: the ports of a node (for the types of inputs and outputs).
        open_ports: parameters left open; each becomes an input whose default is the value
            the parameter had (None when it was unbound or a reference).
        outputs: names written inside -> their docs, declared as outputs.
        description: what it does.

    Raises:
        ValueError: an open port names no node below ``root``, or an output is not written
            inside.
    """
    tree = _fresh(root)
    by_old = {old.id: new for (_, old), (_, new) in zip(root.walk(), tree.walk(), strict=True)}
    inputs: list[SubtreePort] = []
    for spec in open_ports:
        node = by_old.get(spec.node_id)
        port = next((p for p in ports_of(node) if p.name == spec.port), None) if node else None
        if node is None or port is None:
            raise ValueError(f"{spec.port!r} of node {spec.node_id} is not inside {root.label!r}")
        old = node.params.get(spec.port)
        fixed = old is not None and not old.is_ref and old.type is not None
        default = old.value if fixed and old is not None else None
        ptype = ParamType(old.type) if fixed and old is not None and old.type else _one_type(port)
        node.params[spec.port] = Binding.reference(spec.name)
        if any(p.name == spec.name for p in inputs):
            continue  # one input may feed several parameters (OBJECT: found and its pose)
        inputs.append(SubtreePort(spec.name, ptype, spec.doc or port.doc, default))
    reads, writes = _reads_and_writes(tree, ports_of)
    declared = {p.name for p in inputs}
    for ref, ptype in sorted(reads.items()):
        if ref not in writes and ref not in declared:  # read from outside: an input
            inputs.append(SubtreePort(ref, ptype, "read from the plan"))
    declared_outputs = []
    for out_name, doc in (outputs or {}).items():
        if out_name not in writes:
            raise ValueError(f"{out_name} is not written inside {root.label!r}")
        declared_outputs.append(SubtreePort(out_name, writes[out_name], doc))
    return SubtreeSpec(
        new_id(),
        name,
        tree,
        version=0,
        description=description,
        inputs=inputs,
        outputs=declared_outputs,
    )


def instance_name(subtree: SubtreeSpec, params: Mapping[str, Binding]) -> str:
    """What an instance is called until someone names it: the subtree's name and the object
    or waypoint its first input is given ("Pick cup", "Place over bin"), else the name alone.
    """
    first = subtree.inputs[0].name if subtree.inputs else None
    binding = params.get(first) if first is not None else None
    if binding is None or binding.is_ref or binding.type not in _NAMING_TYPES:
        return subtree.name
    thing = getattr(binding.value, "name", "")
    return f"{subtree.name} {thing}" if thing else subtree.name


_NAMING_TYPES = (ParamType.OBJECT, ParamType.WAYPOINT)


def ports_bound_elsewhere(plan: PlanSpec, subtree: SubtreeSpec) -> dict[str, Binding]:
    """What the plan's instances already give a port of ``subtree``'s name and type (the
    first in tick order): a second instance of a library's subtrees is bound as the others
    are ("ABOVE" is "over exit" wherever the plan already says so; an output writes the
    parameter the others write).
    """
    wanted = {port.name: port.type for port in (*subtree.inputs, *subtree.outputs)}
    found: dict[str, Binding] = {}
    for _, node in plan.walk():
        spec = plan.subtree(node.subtree) if node.subtree is not None else None
        if spec is None:
            continue
        for port in (*spec.inputs, *spec.outputs):
            binding = node.params.get(port.name)
            if binding is not None and wanted.get(port.name) is port.type:
                found.setdefault(port.name, binding)
    return found


def instance_of(
    subtree: SubtreeSpec, original: NodeSpec | None = None, open_ports: Sequence[OpenPort] = ()
) -> NodeSpec:
    """An instance of ``subtree``; given the nodes it was made from, bound to do what they did.

    Open inputs keep the value (or reference) the parameter had; inputs read from outside and
    declared outputs are bound to the same names outside.
    """
    params: dict[str, Binding] = {}
    old_bindings = {}
    if original is not None:
        for spec in open_ports:
            node = original.find(spec.node_id)
            if node is not None and spec.port in node.params:
                old_bindings[spec.name] = node.params[spec.port]
    opened = {spec.name for spec in open_ports}
    for port in subtree.inputs:
        if port.name in old_bindings:
            params[port.name] = old_bindings[port.name]
        elif port.name not in opened and original is not None:
            params[port.name] = Binding.reference(port.name)
    if original is not None:
        for port in subtree.outputs:
            params[port.name] = Binding.reference(port.name)
    return NodeSpec(NodeKind.SUBTREE, subtree.name, params=params, subtree=subtree.ref)


def names_used(plan: PlanSpec) -> set[str]:
    """Every name a plan's references, parameters and instances' bindings use."""
    names = {decl.name for decl in plan.parameters}
    for _, node in plan.walk():
        names |= {b.ref for b in node.params.values() if b.ref}
    return names


def detach(plan: PlanSpec, instance: NodeSpec) -> NodeSpec:
    """Plain nodes (new ids) doing what ``instance`` does, in the plan's one scope.

    Inputs are written into the nodes that read them (a fixed value, or the name outside),
    declared outputs become the names they are bound to, shared names stay, and every other
    private name is renamed when the plan already uses it (``PART_POSE`` -> ``PART_POSE_2``).

    Raises:
        ValueError: the instance's subtree is not in the plan.
    """
    if instance.subtree is None or (subtree := plan.subtree(instance.subtree)) is None:
        raise ValueError(f"{instance.label!r}: its subtree is not in this plan")
    values: dict[str, Binding] = {}
    for port in subtree.inputs:
        bound = instance.params.get(port.name)
        if bound is not None and (bound.is_ref or bound.value is not None):
            values[port.name] = bound
        elif port.default is not None:
            values[port.name] = Binding.fixed(port.default, port.type)
    renames = {
        p.name: b.ref for p in subtree.outputs if (b := instance.params.get(p.name)) and b.ref
    }
    used = names_used(plan)
    tree = _fresh(subtree.tree)
    for _, node in tree.walk():
        for port_name, binding in list(node.params.items()):
            if binding.ref is None:
                continue
            name = binding.ref
            if name in values and values[name] is not None:
                node.params[port_name] = values[name]
            elif name in renames:
                node.params[port_name] = Binding.reference(renames[name])
            elif name not in subtree.shared_names:
                renames[name] = _free_name(name, used)
                used.add(renames[name])
                node.params[port_name] = Binding.reference(renames[name])
    tree.name = instance.name or tree.name
    return tree


def _free_name(name: str, used: set[str]) -> str:
    if name not in used:
        return name
    count = 2
    while f"{name}_{count}" in used:
        count += 1
    return f"{name}_{count}"


def update(instance: NodeSpec, newer: SubtreeSpec) -> NodeSpec:
    """A copy of ``instance`` running ``newer``, with the bindings of the ports still there
    (and its conditions).
    """
    ports = {p.name for p in instance_manifest(newer).ports}
    params = {k: b for k, b in instance.params.items() if k in ports}
    return NodeSpec(
        NodeKind.SUBTREE,
        instance.name,
        instance.id,
        params=params,
        subtree=newer.ref,
        conditions=dict(instance.conditions),
    )


def subtrees_in_use(tree: NodeSpec | None, available: Iterable[SubtreeSpec]) -> list[SubtreeSpec]:
    """The definitions the instances below ``tree`` run, nested ones included, in order."""
    by_ref = {s.ref: s for s in available}
    found: dict[SubtreeRef, SubtreeSpec] = {}
    stack = [tree] if tree is not None else []
    while stack:
        node = stack.pop()
        for _, inner in node.walk():
            ref = inner.subtree
            if ref is not None and ref in by_ref and ref not in found:
                found[ref] = by_ref[ref]
                stack.append(by_ref[ref].tree)
    return [s for s in available if s.ref in found]


@dataclass(frozen=True)
class Usage:
    """One instance of a subtree in a plan file."""

    file: Path
    path: str  # the node's path in the plan
    version: int


def find_usages(folder: Path, subtree_id: str) -> tuple[list[Usage], list[str]]:
    """Instances of a subtree in the plan files of a folder (and below); unreadable files named."""
    usages: list[Usage] = []
    problems: list[str] = []
    for file in sorted(folder.rglob(f"*{PLAN_SUFFIX}")):
        try:
            plan = load_plan(file)
        except JsonFileError as exc:
            problems.append(str(exc))
            continue
        for node_path, node in plan.walk():
            if node.subtree is not None and node.subtree.id == subtree_id:
                usages.append(Usage(file, node_path, node.subtree.version))
    return usages, problems
