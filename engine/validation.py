"""Validation of a plan against the operations of a cell (DESIGN.md section 4).

:func:`validate_plan` lists every problem at once, in tree order, each with the node's path
and a sentence a factory worker understands. Errors keep a plan from starting; warnings
(a name that may be read before anything has written it, an output nobody stores) do not.

Reads are checked in tick order against what is *guaranteed* to have been written: after a
node's SUCCESS a Sequence guarantees what all its children wrote, a Selector only what
every child writes, a Parallel what any set of children that meets its success policy
writes, an Inverter or ForceSuccess/ForceFailure nothing, and the looping decorators,
Retry and Timeout what their child writes (an Iterator with a time limit nothing: it may
succeed before its child has finished once). Plan parameters with an initial value are
written before everything.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

from engine.kinds import KIND_PORTS, check_setting, kind_port
from engine.operations import (
    Direction,
    OperationKind,
    OperationManifest,
    OperationNotFound,
    OperationSource,
    PortSpec,
)
from engine.spec import (
    KIND_CATEGORY,
    Binding,
    Category,
    NodeKind,
    NodeSpec,
    PlanSpec,
    SubtreeRef,
    SubtreeSpec,
)
from engine.types import ParamType, check_value

__all__ = [
    "ERROR",
    "WARNING",
    "Severity",
    "Problem",
    "SubtreeSource",
    "validate_plan",
    "has_errors",
]

Severity = Literal["error", "warning"]
ERROR: Severity = "error"
WARNING: Severity = "warning"

_PASS_CHILD = (
    NodeKind.ITERATOR,
    NodeKind.ENFORCE,
    NodeKind.REPEAT,
    NodeKind.RETRY,
    NodeKind.TIMEOUT,
)


class SubtreeSource(Protocol):
    """What validation asks a subtree library (engine.library.Library implements it)."""

    def latest(self, subtree_id: str) -> SubtreeSpec | None:
        """The newest version of a subtree, or None when the library has none."""
        ...


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a plan.

    Attributes:
        severity: "error" (the plan cannot start) or "warning".
        node_id: the node concerned, None for the plan as a whole.
        path: the node's path (``Transfer/pick[1]/move_to[3]``); ``plan`` for the plan as a
            whole, ``parameters`` for its declared parameters.
        field: the port, setting or parameter concerned, if any.
        message: a plain sentence saying what is wrong and, where possible, what to do.
    """

    severity: Severity
    node_id: str | None
    path: str
    field: str | None
    message: str

    def __str__(self) -> str:
        where = " ".join(x for x in (self.path, f"[{self.field}]" if self.field else "") if x)
        return f"{self.severity}: {where + ': ' if where else ''}{self.message}"


def has_errors(problems: Iterable[Problem]) -> bool:
    """True when any problem is an error (the plan must not start)."""
    return any(p.severity == ERROR for p in problems)


@dataclass
class _Writer:
    """A node output (or plan parameter) that writes a blackboard name."""

    label: str
    types: tuple[ParamType, ...]
    node: NodeSpec | None = None
    crossing: bool = False  # written inside a subtree instance, under a shared name


@dataclass
class _Check:
    """State of one validation run."""

    plan: PlanSpec
    source: OperationSource
    paths: dict[int, tuple[int, str]] = field(default_factory=dict)  # id(node) -> (order, path)
    manifests: dict[int, OperationManifest] = field(default_factory=dict)  # id(node) -> manifest
    writers: dict[str, list[_Writer]] = field(default_factory=dict)
    found: list[tuple[int, int, Problem]] = field(default_factory=list)
    # id(instance) -> the shared names its inside reads without writing them first
    crossing_reads: dict[int, tuple[str, ...]] = field(default_factory=dict)

    def add(
        self,
        severity: Severity,
        node: NodeSpec | None,
        message: str,
        name: str | None = None,
        where: str = "plan",
    ) -> None:
        order, path = self.paths[id(node)] if node is not None else (-1, where)
        problem = Problem(severity, node.id if node else None, path, name, message)
        self.found.append((order, len(self.found), problem))


def validate_plan(
    plan: PlanSpec,
    source: OperationSource,
    library: SubtreeSource | None = None,
    *,
    given: Mapping[str, tuple[ParamType, ...]] | None = None,
    stack: tuple[SubtreeRef, ...] = (),
) -> list[Problem]:
    """Every problem of a plan, errors and warnings, sorted in tree order.

    Args:
        plan: the plan to check.
        source: the operations of the cell (manifests and availability).
        library: the subtree library, to say when it has a newer version of a subtree the
            plan's instances run (None: not checked).
        given: names set before the tree starts, with their types (a subtree's inputs and
            shared names, when the inside of a subtree is checked).
        stack: the subtrees being checked around this one (a subtree may not hold itself).

    Returns:
        The problems; empty when the plan is fine. Plan-wide problems come first.
    """
    from engine import subtree_check  # it builds on this module's checks

    check = _Check(plan, source)
    if plan.tree is None:
        check.add(ERROR, None, "The plan is empty: add a node to start from.")
    _check_parameters(check)
    for name, types in (given or {}).items():
        check.writers.setdefault(name, []).append(_Writer(f"the input {name}", types))
    ids: dict[str, str] = {}
    for order, (path, node) in enumerate(plan.walk()):
        check.paths[id(node)] = (order, path)
        if node.id in ids:
            check.add(
                ERROR,
                node,
                f"This node has the same id as the node {ids[node.id]}; "
                "one of them must be given a new id.",
            )
        ids.setdefault(node.id, path)
        _check_structure(check, node)
        if node.kind is NodeKind.OPERATION:
            _check_operation(check, node)
        elif node.kind is NodeKind.SUBTREE:
            subtree_check.check_instance(check, node, library, stack)
    subtree_check.check_crossings(check)
    _check_writer_types(check)
    if plan.tree is not None:
        initial = {p.name for p in plan.parameters if p.value is not None} | set(given or {})
        _check_reads(check, plan.tree, frozenset(initial))
    return [problem for _, _, problem in sorted(check.found, key=lambda f: (f[0], f[1]))]


def _check_parameters(check: _Check) -> None:
    seen: set[str] = set()
    for decl in check.plan.parameters:
        if decl.name in seen:
            message = f"The plan declares the parameter {decl.name} twice."
            check.add(ERROR, None, message, decl.name, "parameters")
        seen.add(decl.name)
        check.writers.setdefault(decl.name, []).append(
            _Writer(f"the plan parameter {decl.name}", (ParamType(decl.type),))
        )
        if decl.value is not None and not check_value(ParamType(decl.type), decl.value):
            check.add(
                ERROR,
                None,
                f"The starting value of {decl.name} is not a {ParamType(decl.type).value}.",
                decl.name,
                "parameters",
            )


def _check_structure(check: _Check, node: NodeSpec) -> None:
    """Kind, number of children and settings of one node."""
    if not isinstance(node.kind, NodeKind):
        check.add(ERROR, node, f"Unknown kind of node {node.kind!r}; it cannot run.")
        return
    category, count, label = KIND_CATEGORY[node.kind], len(node.children), node.label
    if category is Category.DECORATOR and count != 1:
        need = "needs one node below it" if count == 0 else f"can hold only one node, not {count}"
        check.add(ERROR, node, f"{label!r} {need}.")
    elif category is Category.COMPOSITE and count == 0:
        check.add(ERROR, node, f"{label!r} has no nodes below it: add some or remove it.")
    elif category is Category.LEAF and count:
        check.add(ERROR, node, f"{label!r} cannot have nodes below it; it has {count}.")
    if node.kind not in (NodeKind.OPERATION, NodeKind.SUBTREE):
        _check_kind_ports(check, node)
    if node.kind is NodeKind.PARALLEL and count:
        _check_parallel_policy(check, node)
    if node.kind is not NodeKind.OPERATION and node.op:
        check.add(WARNING, node, f"{label!r} is not an operation; its operation is ignored.")


def _stated(params: dict[str, Binding]) -> dict[str, Binding]:
    """The bindings that say something: an empty one (files leave it out) counts as unbound."""
    return {
        k: b for k, b in params.items() if b.is_ref or b.type is not None or b.value is not None
    }


def _setting(node: NodeSpec, name: str) -> Any:
    """A logic node port's fixed value, else its manifest default."""
    binding = node.params.get(name)
    if binding is not None and not binding.is_ref and binding.value is not None:
        return binding.value
    port = kind_port(node.kind, name)
    return None if port is None else port.default


def _check_kind_ports(check: _Check, node: NodeSpec) -> None:
    """The ports of a logic node (engine.kinds.KIND_PORTS): fixed values of the right type."""
    ports = KIND_PORTS.get(node.kind, ())
    params = _stated(node.params)
    for name, binding in params.items():
        port = kind_port(node.kind, name)
        if port is None:
            names = [p.name for p in ports]
            hint = _close(name, names) or f" (it has {', '.join(names) or 'none'})"
            check.add(ERROR, node, f"{node.kind.value} has no setting {name!r}{hint}.", name)
        elif binding.is_ref:
            check.add(
                ERROR,
                node,
                f"{name!r} of {node.label!r} takes a fixed value, not a reference "
                f"to {binding.ref}: the settings of logic nodes are fixed when the plan starts.",
                name,
            )
        elif _check_fixed(check, node, name, binding, port.types, port.choices):
            expected = check_setting(node.kind, name, binding.value)
            if expected is not None:
                check.add(
                    ERROR,
                    node,
                    f"{name!r} of {node.label!r} must be {expected}, not {binding.value!r}.",
                    name,
                )
    for port in ports:
        if port.required and port.name not in params:
            check.add(
                ERROR,
                node,
                f"{node.label!r} needs a value for {port.name!r} ({port.doc}).",
                port.name,
            )


def _check_parallel_policy(check: _Check, node: NodeSpec) -> None:
    count = len(node.children)
    for name in ("success", "failure"):
        wanted = _setting(node, name)
        if isinstance(wanted, (int, float)) and not isinstance(wanted, bool) and wanted > count:
            check.add(
                ERROR,
                node,
                f"{node.label!r} waits for {wanted:g} children to end with "
                f"{name} but has only {count}.",
                name,
            )


def _check_operation(check: _Check, node: NodeSpec) -> None:
    if not node.op:
        check.add(ERROR, node, f"{node.label!r} has no operation chosen.")
        return
    try:
        manifest = check.source.manifest(node.op)
    except OperationNotFound:
        check.add(ERROR, node, f"There is no operation {node.op!r}{_suggest(check, node.op)}.")
        return
    check.manifests[id(node)] = manifest
    availability = check.source.availability(node.op)
    if not availability.available:
        reason = availability.reason or "its capability is not available"
        check.add(ERROR, node, f"{node.label!r} cannot run on this cell: {reason}.")
    params = _stated(node.params)
    _check_bound_ports(check, node, manifest, params)
    _check_unbound_ports(check, node, manifest, params)


def _check_bound_ports(
    check: _Check, node: NodeSpec, manifest: OperationManifest, params: dict[str, Binding]
) -> None:
    for port_name, binding in params.items():
        port = manifest.port(port_name)
        if port is None:
            names = [p.name for p in manifest.ports]
            hint = _close(port_name, names) or f" (it has {', '.join(names) or 'none'})"
            check.add(
                ERROR, node, f"{manifest.id} has no parameter {port_name!r}{hint}.", port_name
            )
        elif port.direction is Direction.OUT:
            _check_output(check, node, port_name, binding, port.types)
        elif not binding.is_ref:
            _check_fixed(check, node, port_name, binding, port.types, port.choices)
            if port.names_kind is not None:
                _check_named_operation(check, node, port, binding)


def _check_unbound_ports(
    check: _Check, node: NodeSpec, manifest: OperationManifest, params: dict[str, Binding]
) -> None:
    for port in manifest.ports:
        if port.name in params:
            continue
        if port.required:
            check.add(
                ERROR,
                node,
                f"{node.label!r} needs a value for {port.name!r} ({_type_names(port.types)}).",
                port.name,
            )
        elif port.direction is Direction.OUT and manifest.kind is OperationKind.QUERY:
            # A query exists for its results; an action's extra results are often not needed.
            check.add(
                WARNING,
                node,
                f"The result {port.name!r} of {node.label!r} is not stored under any name.",
                port.name,
            )


def _check_output(
    check: _Check, node: NodeSpec, port: str, binding: Binding, types: tuple[ParamType, ...]
) -> None:
    if not binding.is_ref:
        check.add(
            ERROR,
            node,
            f"{port!r} is a result of {node.label!r}: give it a name to store "
            "it under, not a fixed value.",
            port,
        )
        return
    assert binding.ref is not None
    check.writers.setdefault(binding.ref, []).append(_Writer(repr(node.label), types, node))


def _check_fixed(
    check: _Check,
    node: NodeSpec,
    port: str,
    binding: Binding,
    types: tuple[ParamType, ...],
    choices: tuple[str, ...],
) -> bool:
    """Check a fixed value against a port's types and choices; True when it fits."""
    ptype = ParamType(binding.type) if binding.type is not None else None
    if ptype is None or not check_value(ptype, binding.value):
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} has no usable value ({_type_names(types)} needed).",
            port,
        )
    elif not _fits(ptype, types):
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} needs {_type_names(types)}, but it is "
            f"set to {_type_names((ptype,))}.",
            port,
        )
    elif choices and ptype is ParamType.TEXT and binding.value not in choices:
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} must be one of "
            f"{', '.join(choices)}, not {binding.value!r}.",
            port,
        )
    else:
        return True
    return False


def _check_named_operation(check: _Check, node: NodeSpec, port: PortSpec, binding: Binding) -> None:
    """A port whose value is an operation id (``names_kind``): that operation must exist,
    be of the kind the port names, be available and need no inputs."""
    kind = port.names_kind
    assert kind is not None
    op_id = binding.value.strip() if isinstance(binding.value, str) else ""
    wanted = f"the id of a {kind.value} operation"
    if not op_id:
        check.add(ERROR, node, f"{port.name!r} of {node.label!r} needs {wanted}.", port.name)
        return
    try:
        named = check.source.manifest(op_id)
    except OperationNotFound:
        hint = _suggest(check, op_id)
        text = f"{port.name!r} of {node.label!r} names no operation: {op_id!r}{hint}."
        check.add(ERROR, node, text, port.name)
        return
    needs = [p.name for p in named.inputs if p.required]
    if named.kind is not kind:
        article = "an" if named.kind.value[0] in "aeiou" else "a"
        problem = f"{op_id} is {article} {named.kind.value}, not a {kind.value}"
    elif not check.source.availability(op_id).available:
        problem = f"{op_id} cannot run on this cell: {check.source.availability(op_id).reason}"
    elif needs:
        problem = f"{op_id} needs {', '.join(needs)}, which {node.label!r} cannot give it"
    else:
        return
    check.add(ERROR, node, f"{port.name!r} of {node.label!r}: {problem}.", port.name)


def _check_writer_types(check: _Check) -> None:
    """One name, one type: every output and declaration of a name must agree."""
    for name, writers in check.writers.items():
        first = writers[0]
        for other in writers[1:]:
            if not (set(first.types) & set(other.types)) and not _any(first.types, other.types):
                check.add(
                    ERROR,
                    other.node,
                    f"{name} is written as {_type_names(first.types)} by "
                    f"{first.label} and as {_type_names(other.types)} by {other.label}.",
                    name,
                )


def _check_reads(check: _Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """Check the references this subtree reads; return what it guarantees after SUCCESS."""
    if node.kind is NodeKind.OPERATION:
        return _operation_reads(check, node, available)
    if node.kind is NodeKind.SUBTREE:
        for name in check.crossing_reads.get(id(node), ()):
            _check_reference(check, node, name, name, (ParamType.ANY,), available)
        return _operation_reads(check, node, available)
    children = node.children
    if node.kind in (NodeKind.SEQUENCE, NodeKind.REACTIVE_SEQUENCE):
        written: frozenset[str] = frozenset()
        for child in children:
            written |= _check_reads(check, child, available | written)
        return written
    results = [_check_reads(check, child, available) for child in children]
    if node.kind is NodeKind.PARALLEL:
        return _parallel_guarantee(node, results)
    if node.kind in (NodeKind.SELECTOR, NodeKind.REACTIVE_SELECTOR):
        return frozenset.intersection(*results) if results else frozenset()
    if node.kind is NodeKind.ITERATOR and _setting(node, "timeout"):
        return frozenset()
    if node.kind in _PASS_CHILD and len(results) == 1:
        return results[0]
    return frozenset()


def _parallel_guarantee(node: NodeSpec, results: list[frozenset[str]]) -> frozenset[str]:
    """A name is guaranteed when any set of children that meets the success policy has a
    child that writes it, i.e. fewer children than the policy needs leave it unwritten."""
    policy = _setting(node, "success")
    need = len(results) if policy == "all" else 1 if policy == "any" else policy
    if not isinstance(need, (int, float)) or isinstance(need, bool):
        return frozenset()
    every = frozenset().union(*results)
    return frozenset(n for n in every if sum(n not in r for r in results) < need)


def _operation_reads(check: _Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    manifest = check.manifests.get(id(node))
    written: set[str] = set()
    for port_name, binding in node.params.items():
        port = manifest.port(port_name) if manifest is not None else None
        if binding.ref is None or port is None:
            continue
        if port.direction is Direction.OUT:
            written.add(binding.ref)
            continue
        _check_reference(check, node, port_name, binding.ref, port.types, available)
    return frozenset(written)


def _check_reference(
    check: _Check,
    node: NodeSpec,
    port: str,
    name: str,
    types: tuple[ParamType, ...],
    available: frozenset[str],
) -> None:
    writers = check.writers.get(name)
    if not writers:
        check.add(
            ERROR,
            node,
            f"Nothing sets {name}, which {node.label!r} reads for {port!r}: "
            "add a query that writes it or declare it as a plan parameter.",
            port,
        )
        return
    wrong = [w for w in writers if not _fits_any(w.types, types)]
    if wrong:
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} needs {_type_names(types)}, but "
            f"{name} is {_type_names(wrong[0].types)} (from {wrong[0].label}).",
            port,
        )
    if name not in available:
        check.add(
            WARNING,
            node,
            f"{node.label!r} may read {name} before anything has set it: "
            "give it a starting value, or set it earlier in the same sequence.",
            port,
        )


def _fits(ptype: ParamType, accepted: Sequence[ParamType]) -> bool:
    return ptype in accepted or ParamType.ANY in accepted


def _fits_any(given: Sequence[ParamType], accepted: Sequence[ParamType]) -> bool:
    return ParamType.ANY in given or any(_fits(t, accepted) for t in given)


def _any(a: Sequence[ParamType], b: Sequence[ParamType]) -> bool:
    return ParamType.ANY in a or ParamType.ANY in b


def _type_names(types: Sequence[ParamType]) -> str:
    names = [f"a {ParamType(t).value}" for t in types]
    return " or ".join(names) if names else "a value"


def _close(word: str, candidates: Iterable[str]) -> str:
    matches = difflib.get_close_matches(word, list(candidates), n=3, cutoff=0.6)
    return f" (did you mean {' or '.join(repr(m) for m in matches)}?)" if matches else ""


def _suggest(check: _Check, op: str) -> str:
    """Close operation ids, from the source's list of manifests when it has one."""
    listing = getattr(check.source, "manifests", None)
    ids = [m.id for m in listing()] if callable(listing) else []
    return _close(op, [*ids, *check.source.aliases()])
