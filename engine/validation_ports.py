"""The pieces of plan validation that checks share: problems, the run's state, port checks.

:mod:`engine.validation` checks a plan with them; :mod:`engine.subtree_check` checks subtree
instances with the same port checks (an instance's inputs are ports).
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Literal, Protocol

from engine.operations import (
    Direction,
    OperationKind,
    OperationManifest,
    OperationNotFound,
    OperationSource,
    PortSpec,
)
from engine.spec import Binding, NodeSpec, PlanSpec, SubtreeSpec
from engine.types import ParamType, check_value, with_article

__all__ = [
    "ERROR",
    "WARNING",
    "Check",
    "Problem",
    "Severity",
    "SubtreeSource",
    "Writer",
    "check_bound_ports",
    "check_fixed",
    "check_output",
    "check_unbound_ports",
    "close_names",
    "fits",
    "fits_any",
    "any_type",
    "has_errors",
    "stated",
    "suggest",
    "type_names",
]

Severity = Literal["error", "warning"]
ERROR: Severity = "error"
WARNING: Severity = "warning"


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
class Writer:
    """A node output (or plan parameter) that writes a blackboard name."""

    label: str
    types: tuple[ParamType, ...]
    node: NodeSpec | None = None
    crossing: bool = False  # written inside a subtree instance, under a shared name


@dataclass
class Check:
    """State of one validation run."""

    plan: PlanSpec
    source: OperationSource
    paths: dict[int, tuple[int, str]] = field(default_factory=dict)  # id(node) -> (order, path)
    manifests: dict[int, OperationManifest] = field(default_factory=dict)  # id(node) -> manifest
    writers: dict[str, list[Writer]] = field(default_factory=dict)
    found: list[tuple[int, int, Problem]] = field(default_factory=list)
    # id(instance) -> the shared names its inside reads without writing them first
    crossing_reads: dict[int, tuple[str, ...]] = field(default_factory=dict)
    inside: bool = False  # the plan checked is the inside of a subtree

    def name_of(self, ref: str) -> str | None:
        """The name a reference stands for: ``@name`` (BehaviorTree.CPP's top-level entry)
        is ``name`` at the top; inside a subtree it is not checked (None).
        """
        if not ref.startswith("@"):
            return ref
        return None if self.inside else ref[1:]

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


def stated(params: dict[str, Binding]) -> dict[str, Binding]:
    """The bindings that say something: an empty one (files leave it out) counts as unbound."""
    return {
        k: b for k, b in params.items() if b.is_ref or b.type is not None or b.value is not None
    }


def check_bound_ports(
    check: Check, node: NodeSpec, manifest: OperationManifest, params: dict[str, Binding]
) -> None:
    """Check each parameter a node binds: the port exists, a result is stored under a name, a
    fixed value fits.
    """
    for port_name, binding in params.items():
        port = manifest.port(port_name)
        if port is None:
            names = [p.name for p in manifest.ports]
            hint = close_names(port_name, names) or f" (it has {', '.join(names) or 'none'})"
            check.add(
                ERROR, node, f"{manifest.id} has no parameter {port_name!r}{hint}.", port_name
            )
        elif port.direction is Direction.OUT:
            check_output(check, node, port_name, binding, port.types)
        elif not binding.is_ref:
            check_fixed(check, node, port_name, binding, port.types, port.choices)
            if port.names_kind is not None:
                check_named_operation(check, node, port, binding)


def check_unbound_ports(
    check: Check, node: NodeSpec, manifest: OperationManifest, params: dict[str, Binding]
) -> None:
    """Check the ports a node leaves unbound: a required one is an error, a query's unstored
    result a warning.
    """
    for port in manifest.ports:
        if port.name in params:
            continue
        if port.required:
            check.add(
                ERROR,
                node,
                f"{node.label!r} needs a value for {port.name!r} ({type_names(port.types)}).",
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


def check_output(
    check: Check, node: NodeSpec, port: str, binding: Binding, types: tuple[ParamType, ...]
) -> None:
    """Check a result port is bound to a name, and record the node as a writer of that name."""
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
    name = check.name_of(binding.ref)
    if name is not None:
        check.writers.setdefault(name, []).append(Writer(repr(node.label), types, node))


def check_fixed(
    check: Check,
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
            f"{port!r} of {node.label!r} has no usable value ({type_names(types)} needed).",
            port,
        )
    elif not fits(ptype, types):
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} needs {type_names(types)}, but it is "
            f"set to {type_names((ptype,))}.",
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


def check_named_operation(check: Check, node: NodeSpec, port: PortSpec, binding: Binding) -> None:
    """A port whose value is an operation id (``names_kind``): that operation must exist,
    be of the kind the port names, be available and need no inputs.
    """
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
        hint = suggest(check, op_id)
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


def fits(ptype: ParamType, accepted: Sequence[ParamType]) -> bool:
    """True when a value of ``ptype`` is accepted by a port of the ``accepted`` types."""
    return ptype in accepted or ParamType.ANY in accepted


def fits_any(given: Sequence[ParamType], accepted: Sequence[ParamType]) -> bool:
    """True when one of the ``given`` types (or Any) fits the ``accepted`` ones."""
    return ParamType.ANY in given or any(fits(t, accepted) for t in given)


def any_type(a: Sequence[ParamType], b: Sequence[ParamType]) -> bool:
    """True when either side accepts any type."""
    return ParamType.ANY in a or ParamType.ANY in b


def type_names(types: Sequence[ParamType]) -> str:
    """The types in words: "a Pose or a Waypoint" ("a value" for none)."""
    names = [
        "a value of any type" if t == ParamType.ANY else with_article(ParamType(t).value)
        for t in types
    ]
    return " or ".join(names) if names else "a value"


def close_names(word: str, candidates: Iterable[str]) -> str:
    """A " (did you mean ...?)" hint naming up to three ``candidates`` close to ``word``; ""
    when none is.
    """
    matches = difflib.get_close_matches(word, list(candidates), n=3, cutoff=0.6)
    return f" (did you mean {' or '.join(repr(m) for m in matches)}?)" if matches else ""


def suggest(check: Check, op: str) -> str:
    """Close operation ids, from the source's list of manifests when it has one."""
    listing = getattr(check.source, "manifests", None)
    ids = [m.id for m in listing()] if callable(listing) else []
    return close_names(op, [*ids, *check.source.aliases()])
