"""Validation of subtree instances (part of :func:`engine.validation.validate_plan`).

An instance's bindings are checked like an operation's ports (its manifest is built from the
subtree's declared inputs and outputs); the inside is checked as a tree of its own whose
inputs and shared names are given, and its problems are reported at the instance's path.
A name that crosses scopes (a subtree's ``shared_names``) written inside an instance and also
by another instance or by the plan is a collision: reported, since each overwrites the other.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.instances import instance_manifest
from engine.operations import Direction
from engine.spec import NodeKind, NodeSpec, PlanSpec, SubtreeRef, SubtreeSpec
from engine.types import ParamType
from engine.validation_ports import (
    ERROR,
    WARNING,
    Check,
    Problem,
    SubtreeSource,
    Writer,
    check_bound_ports,
    check_unbound_ports,
    stated,
)

# validate_plan, passed in by engine.validation (which imports this module)
Validate = Callable[..., list[Problem]]

__all__ = ["check_instance", "check_crossings", "inner_writes"]


def check_instance(
    check: Check,
    node: NodeSpec,
    library: SubtreeSource | None,
    stack: tuple[SubtreeRef, ...],
    validate: Validate,
) -> None:
    """The subtree an instance runs, its bindings, its inside, and the library's version."""
    if node.subtree is None:
        check.add(ERROR, node, f"{node.label!r} does not say which subtree it runs.")
        return
    ref = node.subtree
    subtree = check.plan.subtree(ref)
    latest = library.latest(ref.id) if library is not None else None
    if subtree is None:
        hint = (
            f" The library has version {latest.version} of {latest.name!r}: update the instance."
            if latest is not None
            else " Add it to the library or remove the instance."
        )
        check.add(
            ERROR,
            node,
            f"{node.label!r} runs the subtree {ref.id!r} version {ref.version}, which is "
            f"neither in this plan nor in the library.{hint}",
        )
        return
    if latest is not None and latest.version > subtree.version:
        check.add(
            WARNING,
            node,
            f"The library has a newer version of {subtree.name!r} (version {latest.version}, "
            f"{latest.date or 'no date'}; this plan uses version {subtree.version}): "
            "update the instance to use it.",
        )
    if ref in stack:
        check.add(ERROR, node, f"The subtree {subtree.name!r} holds an instance of itself.")
        return
    manifest = instance_manifest(subtree)
    check.manifests[id(node)] = manifest
    params = stated(node.params)
    check_bound_ports(check, node, manifest, params)
    check_unbound_ports(check, node, manifest, params)
    _check_definition(check, node, subtree)
    _check_inside(check, node, subtree, library, (*stack, ref), validate)
    _add_crossings(check, node, subtree)


def _check_definition(check: Check, node: NodeSpec, subtree: SubtreeSpec) -> None:
    declared = {p.name for p in [*subtree.inputs, *subtree.outputs]}
    for name in subtree.shared_names:
        if name in declared:
            check.add(
                ERROR,
                node,
                f"{name} of the subtree {subtree.name!r} is both declared as an input or "
                "output and shared across scopes: make it one or the other.",
                name,
            )


def _check_inside(
    check: Check,
    node: NodeSpec,
    subtree: SubtreeSpec,
    library: SubtreeSource | None,
    stack: tuple[SubtreeRef, ...],
    validate: Validate,
) -> None:
    """The inside, checked as a tree of its own, its problems reported at the instance."""
    given: dict[str, tuple[ParamType, ...]] = {p.name: (ParamType(p.type),) for p in subtree.inputs}
    for name in subtree.shared_names:
        given.setdefault(name, (ParamType.ANY,))
    inner = PlanSpec(tree=subtree.tree, name=subtree.name, subtrees=check.plan.subtrees)
    problems = validate(inner, check.source, library, given=given, stack=stack)
    order, path = check.paths[id(node)]
    for problem in problems:
        inside = Problem(
            problem.severity, node.id, f"{path}/{problem.path}", problem.field, problem.message
        )
        check.found.append((order, len(check.found), inside))
    written = inner_writes(subtree, check)
    for port in subtree.outputs:
        if port.name not in written:
            check.add(
                ERROR,
                node,
                f"The output {port.name} of {subtree.name!r} is written by nothing inside it.",
                port.name,
            )


def inner_writes(subtree: SubtreeSpec, check: Check) -> dict[str, tuple[ParamType, ...]]:
    """Names the inside writes (operation results and nested instances' outputs), with types."""
    written: dict[str, tuple[ParamType, ...]] = {}
    for _, inner in subtree.tree.walk():
        if inner.kind is NodeKind.OPERATION and inner.op:
            try:
                manifest = check.source.manifest(inner.op)
            except Exception:  # reported by the inside's own check
                continue
        elif inner.kind is NodeKind.SUBTREE and inner.subtree is not None:
            nested = check.plan.subtree(inner.subtree)
            if nested is None:
                continue
            manifest = instance_manifest(nested)
        else:
            continue
        for port in manifest.ports:
            binding = inner.params.get(port.name)
            if port.direction is Direction.OUT and binding is not None and binding.ref:
                written[binding.ref] = port.types
    return written


def _add_crossings(check: Check, node: NodeSpec, subtree: SubtreeSpec) -> None:
    """Shared names: writes inside count in this scope; reads inside need a writer here.
    A write inside to ``@name`` writes the top-level name (counted when this is the top).
    """
    written = inner_writes(subtree, check)
    for ref, types in written.items():
        name = check.name_of(ref) if ref.startswith("@") else None
        if name is not None:
            check.writers.setdefault(name, []).append(Writer(repr(node.label), types, node))
    for name in subtree.shared_names:
        if name in written:
            writer = Writer(repr(node.label), written[name], node, crossing=True)
            check.writers.setdefault(name, []).append(writer)
    reads = [name for name in subtree.shared_names if name not in written]
    check.crossing_reads[id(node)] = tuple(reads)


def check_crossings(check: Check) -> None:
    """A shared name written inside an instance and by anything else in this scope collides."""
    for name, writers in check.writers.items():
        crossing = [w for w in writers if w.crossing]
        for writer in crossing:
            others = [w.label for w in writers if w is not writer and w.node is not None]
            if others:
                check.add(
                    WARNING,
                    writer.node,
                    f"{name} crosses scopes out of {writer.label} and is also written by "
                    f"{', '.join(others)}: each overwrites the other. Rename one, or bind an "
                    "output of the subtree instead of sharing the name.",
                    name,
                )
