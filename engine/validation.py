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

A node's pre- and post-conditions (engine.conditions) are scripts like a Script node's: one
that does not parse is an error naming the line and column; the names they write are
written (of any type), the names they read are checked as references, pre-conditions
before the node and post-conditions after it. A node that may be passed over by its
conditions (success_if, skip_if, while) guarantees nothing it writes itself.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

from engine.conditions import PRE_CONDITIONS, Condition
from engine.kinds import KIND_PORTS, check_setting, kind_port
from engine.operations import (
    BoundPort,
    Direction,
    OperationNotFound,
    OperationSource,
)
from engine.port_text import braced
from engine.queue_loop import LOOP_TYPES, parse_queue
from engine.script import ScriptError, ScriptNames, parse_script, script_names
from engine.spec import (
    KIND_CATEGORY,
    Category,
    NodeKind,
    NodeSpec,
    PlanSpec,
    SubtreeRef,
)
from engine.subtree_check import check_crossings, check_instance
from engine.types import ParamType, check_value
from engine.validation_ports import (
    ERROR,
    WARNING,
    Check,
    Problem,
    Severity,
    SubtreeSource,
    Writer,
    any_type,
    check_bound_ports,
    check_fixed,
    check_unbound_ports,
    close_names,
    fits_any,
    has_errors,
    stated,
    suggest,
    type_names,
)

EMPTY_PLAN = "The plan is empty: add a node to start from."

__all__ = [
    "EMPTY_PLAN",
    "ERROR",
    "WARNING",
    "Severity",
    "Problem",
    "SubtreeSource",
    "validate_plan",
    "has_errors",
]


_PASS_CHILD = (
    NodeKind.ITERATOR,
    NodeKind.ENFORCE,
    NodeKind.REPEAT,
    NodeKind.RETRY,
    NodeKind.TIMEOUT,
)


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
    check = Check(plan, source, inside=given is not None or bool(stack))
    if plan.tree is None:
        check.add(ERROR, None, EMPTY_PLAN)
    _check_parameters(check)
    for name, types in (given or {}).items():
        check.writers.setdefault(name, []).append(Writer(f"the input {name}", types))
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
            check_instance(check, node, library, stack, validate_plan)
        elif node.kind in _SCRIPTS:
            _script_writes(check, node)
        if node.conditions:
            _condition_writes(check, node)
    check_crossings(check)
    _check_writer_types(check)
    _check_rules(check)
    if plan.tree is not None:
        initial = {p.name for p in plan.parameters if p.value is not None} | set(given or {})
        _check_reads(check, plan.tree, frozenset(initial))
    return [problem for _, _, problem in sorted(check.found, key=lambda f: (f[0], f[1]))]


_SCRIPTS = (NodeKind.SCRIPT, NodeKind.SCRIPT_CONDITION)
# Composites whose children run one after the other, each after the one before succeeded.
_SEQUENCES = (
    NodeKind.SEQUENCE,
    NodeKind.REACTIVE_SEQUENCE,
    NodeKind.SEQUENCE_WITH_MEMORY,
    NodeKind.ASYNC_SEQUENCE,
)


def _names_of_script(node: NodeSpec) -> ScriptNames | None:
    """What a script node reads and writes; None without a script that parses."""
    binding = node.params.get("code")
    if binding is None or binding.is_ref or not isinstance(binding.value, str):
        return None
    try:
        return script_names(parse_script(binding.value))
    except ScriptError:
        return None  # reported with the node's settings


def _script_writes(check: Check, node: NodeSpec) -> None:
    """A script's assignments write their names (of any type: a script converts)."""
    names = _names_of_script(node)
    for name in names.writes if names is not None else ():
        check.writers.setdefault(name, []).append(
            Writer(f"the script of {node.label}", (ParamType.ANY,), node)
        )


def _script_reads(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """A script reads names (checked as an operation's references); after SUCCESS it has
    written its statements' own assignments.
    """
    names = _names_of_script(node)
    if names is None:
        return frozenset()
    for name in names.reads:
        _check_reference(check, node, "code", name, (ParamType.ANY,), available)
    return frozenset(names.sure)


def _parsed_conditions(node: NodeSpec) -> Iterator[tuple[Condition, ScriptNames | ScriptError]]:
    """Each condition a node has, in the fixed order, with what its script reads and writes
    (or why it does not parse).
    """
    given = {Condition(c): text for c, text in node.conditions.items()}
    for condition in Condition:
        text = given.get(condition, "")
        if not text.strip():
            continue
        try:
            yield condition, script_names(parse_script(text))
        except ScriptError as exc:
            yield condition, exc


def _condition_names(node: NodeSpec) -> dict[Condition, ScriptNames]:
    """What each condition of a node that parses reads and writes, in the fixed order (one
    that does not parse is reported by _condition_writes).
    """
    return {c: names for c, names in _parsed_conditions(node) if not isinstance(names, ScriptError)}


def _condition_label(condition: Condition) -> str:
    return condition.value.replace("_", " ")


def _condition_writes(check: Check, node: NodeSpec) -> None:
    """A condition that does not parse is an error; the names conditions write are written."""
    for condition, names in _parsed_conditions(node):
        if isinstance(names, ScriptError):
            check.add(
                ERROR,
                node,
                f"The {_condition_label(condition)} condition of {node.label!r} is not a script "
                f"of BehaviorTree.CPP's language: {names}.",
                condition.value,
            )
            continue
        for name in names.writes:
            check.writers.setdefault(name, []).append(
                Writer(
                    f"the {_condition_label(condition)} condition of {node.label}",
                    (ParamType.ANY,),
                    node,
                )
            )


def _condition_reads(
    check: Check,
    node: NodeSpec,
    names: dict[Condition, ScriptNames],
    conditions: tuple[Condition, ...],
    available: frozenset[str],
) -> frozenset[str]:
    """Check what these conditions read, each after the ones before it; what they surely wrote."""
    written: frozenset[str] = frozenset()
    for condition in conditions:
        found = names.get(condition)
        if found is None:
            continue
        for name in found.reads:
            _check_reference(
                check, node, condition.value, name, (ParamType.ANY,), available | written
            )
        written |= frozenset(found.sure)
    return written


_PASSED_OVER = (Condition.SUCCESS_IF, Condition.SKIP_IF, Condition.WHILE)


def _check_reads(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """Check the references this subtree reads, its conditions' included; return what it
    guarantees after SUCCESS (or after it was passed over: a Sequence goes on past SKIPPED).
    """
    if not node.conditions:
        return _check_reads_of(check, node, available)
    names = _condition_names(node)
    # The pre-conditions are checked one after the other; a later one runs only when the
    # earlier ones did not decide, so their sure writes hold for the later ones.
    before = _condition_reads(check, node, names, PRE_CONDITIONS, available)
    written = _check_reads_of(check, node, available | before)
    after_success = _condition_reads(
        check, node, names, (Condition.ON_SUCCESS, Condition.POST), available | before | written
    )
    _condition_reads(check, node, names, (Condition.ON_FAILURE,), available | before)
    _condition_reads(check, node, names, (Condition.ON_HALTED,), available | before)
    if any(node.conditions.get(c, "").strip() for c in _PASSED_OVER):
        return frozenset()
    return written | after_success


def _check_parameters(check: Check) -> None:
    seen: set[str] = set()
    for decl in check.plan.parameters:
        if decl.name in seen:
            message = f"The plan declares the parameter {decl.name} twice."
            check.add(ERROR, None, message, decl.name, "parameters")
        seen.add(decl.name)
        check.writers.setdefault(decl.name, []).append(
            Writer(f"the plan parameter {decl.name}", (ParamType(decl.type),))
        )
        if decl.value is not None and not check_value(ParamType(decl.type), decl.value):
            check.add(
                ERROR,
                None,
                f"The starting value of {decl.name} is not a {ParamType(decl.type).value}.",
                decl.name,
                "parameters",
            )


def _check_structure(check: Check, node: NodeSpec) -> None:
    """Kind, number of children and settings of one node."""
    if not isinstance(node.kind, NodeKind):
        check.add(ERROR, node, f"Unknown kind of node {node.kind!r}; it cannot run.")
        return
    _check_children(check, node)
    count, label = len(node.children), node.label
    if node.kind not in (NodeKind.OPERATION, NodeKind.SUBTREE):
        _check_kind_ports(check, node)
    if count:
        _check_kind_rules(check, node)
    if node.kind is NodeKind.SET_BLACKBOARD and (key := _written_key(node)):
        check.writers.setdefault(key, []).append(Writer(repr(label), (ParamType.ANY,), node))
    if node.kind is NodeKind.CATCH:
        key = _setting(node, "error")
        if isinstance(key, str) and key:  # it writes the caught error there, as Text
            check.writers.setdefault(key, []).append(Writer(repr(label), (ParamType.TEXT,), node))
    if node.kind is not NodeKind.OPERATION and node.op:
        check.add(WARNING, node, f"{label!r} is not an operation; its operation is ignored.")


def _check_children(check: Check, node: NodeSpec) -> None:
    """The number of children the node's kind takes."""
    category, count, label = KIND_CATEGORY[node.kind], len(node.children), node.label
    if category is Category.DECORATOR and count != 1:
        need = "needs one node below it" if count == 0 else f"can hold only one node, not {count}"
        check.add(ERROR, node, f"{label!r} {need}.")
    elif node.kind in _CHILD_COUNTS and count not in _CHILD_COUNTS[node.kind][0]:
        check.add(ERROR, node, f"{label!r} needs {_CHILD_COUNTS[node.kind][1]}; it has {count}.")
    elif node.kind is NodeKind.CATCH and count != 2:
        check.add(
            ERROR,
            node,
            f"{label!r} needs two nodes below it, what it tries and what handles its "
            f"failure; it has {count}.",
        )
    elif category is Category.COMPOSITE and count == 0:
        check.add(ERROR, node, f"{label!r} has no nodes below it: add some or remove it.")
    elif category is Category.LEAF and count:
        check.add(ERROR, node, f"{label!r} cannot have nodes below it; it has {count}.")


def _check_kind_rules(check: Check, node: NodeSpec) -> None:
    """Settings checked against the number of children."""
    if node.kind is NodeKind.PARALLEL:
        _check_parallel_policy(check, node)
    elif node.kind is NodeKind.PARALLEL_ALL:
        _check_parallel_all(check, node)
    elif node.kind is NodeKind.SWITCH:
        _check_switch_cases(check, node)
    elif node.kind is NodeKind.LOOP:
        _check_loop(check, node)


# How many children some composites take: (the counts allowed, what to say).
_CHILD_COUNTS: dict[NodeKind, tuple[range, str]] = {
    NodeKind.IF_THEN_ELSE: (range(2, 4), "two or three nodes below it: if, then, else"),
    NodeKind.WHILE_DO_ELSE: (range(2, 4), "two or three nodes below it: while, do, else"),
    NodeKind.SWITCH: (range(3, 8), "from three to seven nodes below it: 2 to 6 cases, a default"),
    NodeKind.TRY_CATCH: (range(2, 1 << 16), "two or more nodes below it: try, then catch"),
}


def _written_key(node: NodeSpec) -> str | None:
    """The entry a SetBlackboard writes when its output_key names it (not ``{key}``)."""
    key = _setting(node, "output_key")
    if not isinstance(key, str) or not key.strip() or braced(key) is not None:
        return None
    return key.strip()


def _check_switch_cases(check: Check, node: NodeSpec) -> None:
    cases = len(node.children) - 1
    for name, binding in node.params.items():
        if name.startswith("case_") and int(name[5:]) > cases and binding.value not in ("", None):
            check.add(
                ERROR,
                node,
                f"{node.label!r} has {cases} cases (one node each, and a default last), so "
                f"{name!r} has no node to run.",
                name,
            )


_LOOP_VALUE_TYPES = {
    "int": ParamType.NUMBER,
    "double": ParamType.NUMBER,
    "bool": ParamType.BOOL,
    "string": ParamType.TEXT,
}


def _loop_value_key(node: NodeSpec) -> str | None:
    """The entry a Loop writes its values to (``{key}``), or None."""
    value = _setting(node, "value")
    return braced(value) or None if isinstance(value, str) else None


def _check_loop(check: Check, node: NodeSpec) -> None:
    """A Loop writes to ``{key}``; a queue written out must hold values of its type."""
    of = _setting(node, "type")
    key = _loop_value_key(node)
    if key is None:
        value = _setting(node, "value")
        if value is not None:
            check.add(
                ERROR,
                node,
                f"'value' of {node.label!r} names the entry the values go to, as {{key}}, "
                f"not {value!r}.",
                "value",
            )
    elif of in _LOOP_VALUE_TYPES:
        writer = Writer(repr(node.label), (_LOOP_VALUE_TYPES[of],), node)
        check.writers.setdefault(key, []).append(writer)
    queue = _setting(node, "queue")
    if isinstance(queue, str) and braced(queue) is None and of in LOOP_TYPES:
        try:
            parse_queue(queue, of)
        except ValueError as exc:
            check.add(
                ERROR, node, f"'queue' of {node.label!r} must hold {of} values: {exc}.", "queue"
            )


def _check_parallel_all(check: Check, node: NodeSpec) -> None:
    count = len(node.children)
    wanted = _setting(node, "max_failures")
    if isinstance(wanted, (int, float)) and wanted > count:
        check.add(
            ERROR,
            node,
            f"{node.label!r} fails after {wanted:g} failures but has only {count} children.",
            "max_failures",
        )


def _setting(node: NodeSpec, name: str) -> Any:
    """A logic node port's fixed value, else its manifest default."""
    binding = node.params.get(name)
    if binding is not None and not binding.is_ref and binding.value is not None:
        return binding.value
    port = kind_port(node.kind, name)
    return None if port is None else port.default


def _check_kind_ports(check: Check, node: NodeSpec) -> None:
    """The ports of a logic node (engine.kinds.KIND_PORTS): fixed values of the right type."""
    ports = KIND_PORTS.get(node.kind, ())
    params = stated(node.params)
    for name, binding in params.items():
        port = kind_port(node.kind, name)
        if port is None:
            names = [p.name for p in ports]
            hint = close_names(name, names) or f" (it has {', '.join(names) or 'none'})"
            check.add(ERROR, node, f"{node.kind.value} has no setting {name!r}{hint}.", name)
        elif binding.is_ref:
            check.add(
                ERROR,
                node,
                f"{name!r} of {node.label!r} takes a fixed value, not a reference "
                f"to {binding.ref}: the settings of logic nodes are fixed when the plan starts.",
                name,
            )
        elif check_fixed(check, node, name, binding, port.types, port.choices):
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


def _check_parallel_policy(check: Check, node: NodeSpec) -> None:
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


def _check_operation(check: Check, node: NodeSpec) -> None:
    if not node.op:
        check.add(ERROR, node, f"{node.label!r} has no operation chosen.")
        return
    try:
        manifest = check.source.manifest(node.op)
    except OperationNotFound:
        check.add(ERROR, node, f"There is no operation {node.op!r}{suggest(check, node.op)}.")
        return
    check.manifests[id(node)] = manifest
    availability = check.source.availability(node.op)
    if not availability.available:
        reason = availability.reason or "its capability is not available"
        check.add(ERROR, node, f"{node.label!r} cannot run on this cell: {reason}.")
    params = stated(node.params)
    check_bound_ports(check, node, manifest, params)
    check_unbound_ports(check, node, manifest, params)


def _check_rules(check: Check) -> None:
    """The checks across ports that operations declare (``OperationManifest.rules``)."""
    for _path, node in check.plan.walk():
        manifest = check.manifests.get(id(node))
        if manifest is None or not manifest.rules:
            continue
        bound: dict[str, BoundPort] = {}
        for name, binding in stated(node.params).items():
            port = manifest.port(name)
            if port is None or port.direction is not Direction.IN:
                continue
            if binding.ref is not None:
                writers = check.writers.get(binding.ref) or []
                types = tuple({t: None for w in writers for t in w.types}) or (ParamType.ANY,)
                bound[name] = BoundPort(types, ref=binding.ref)
            elif binding.type is not None:
                bound[name] = BoundPort((ParamType(binding.type),), binding.value)
        for rule in manifest.rules:
            for port_name, message in rule(bound):
                check.add(ERROR, node, f"{node.label!r}: {message}", port_name)


def _check_writer_types(check: Check) -> None:
    """One name, one type: every output and declaration of a name must agree."""
    for name, writers in check.writers.items():
        first = writers[0]
        for other in writers[1:]:
            if not (set(first.types) & set(other.types)) and not any_type(first.types, other.types):
                check.add(
                    ERROR,
                    other.node,
                    f"{name} is written as {type_names(first.types)} by "
                    f"{first.label} and as {type_names(other.types)} by {other.label}.",
                    name,
                )


def _check_reads_of(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """:func:`_check_reads` of the node itself (its kind), without its conditions."""
    if KIND_CATEGORY.get(node.kind) is Category.LEAF:
        return _leaf_reads(check, node, available)
    children = node.children
    if node.kind in _SEQUENCES:
        written: frozenset[str] = frozenset()
        for child in children:
            written |= _check_reads(check, child, available | written)
        return written
    if node.kind is NodeKind.CATCH and len(children) == 2:
        return _catch_reads(check, node, available)
    if node.kind is NodeKind.LOOP and (key := _loop_value_key(node)):
        available = available | {key}  # written before the child runs
    results = [_check_reads(check, child, available) for child in children]
    if node.kind is NodeKind.PARALLEL:
        return _parallel_guarantee(node, results)
    if node.kind in (NodeKind.SELECTOR, NodeKind.REACTIVE_SELECTOR, NodeKind.ASYNC_FALLBACK):
        return frozenset.intersection(*results) if results else frozenset()
    if node.kind is NodeKind.ITERATOR and _setting(node, "timeout"):
        return frozenset()
    if node.kind in _PASS_CHILD and len(results) == 1:
        return results[0]
    return frozenset()


def _leaf_reads(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """:func:`_check_reads_of` of a leaf."""
    if node.kind is NodeKind.OPERATION:
        return _operation_reads(check, node, available)
    if node.kind in _SCRIPTS:
        return _script_reads(check, node, available)
    if node.kind is NodeKind.SUBTREE:
        for name in check.crossing_reads.get(id(node), ()):
            _check_reference(check, node, name, name, (ParamType.ANY,), available)
        return _operation_reads(check, node, available)
    if node.kind is NodeKind.SET_BLACKBOARD:
        key = _written_key(node)
        return frozenset({key}) if key else frozenset()
    return frozenset()


def _catch_reads(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    """The handler may read the caught error; after SUCCESS only what both ways wrote."""
    body, handler = node.children
    key = _setting(node, "error")
    caught = frozenset({key}) if isinstance(key, str) and key else frozenset()
    from_body = _check_reads(check, body, available)
    from_handler = _check_reads(check, handler, available | caught) | caught
    return from_body & from_handler


def _parallel_guarantee(node: NodeSpec, results: list[frozenset[str]]) -> frozenset[str]:
    """A name is guaranteed when any set of children that meets the success policy has a
    child that writes it, i.e. fewer children than the policy needs leave it unwritten.
    """
    policy = _setting(node, "success")
    need = len(results) if policy == "all" else 1 if policy == "any" else policy
    if not isinstance(need, (int, float)) or isinstance(need, bool):
        return frozenset()
    if need < 0:  # counted back from all children
        need = max(len(results) + need + 1, 0)
    every = frozenset().union(*results)
    return frozenset(n for n in every if sum(n not in r for r in results) < need)


def _operation_reads(check: Check, node: NodeSpec, available: frozenset[str]) -> frozenset[str]:
    manifest = check.manifests.get(id(node))
    written: set[str] = set()
    for port_name, binding in node.params.items():
        port = manifest.port(port_name) if manifest is not None else None
        if binding.ref is None or port is None:
            continue
        name = check.name_of(binding.ref)
        if name is None:
            continue  # a top-level entry, from inside a subtree
        if port.direction is Direction.OUT:
            written.add(name)
            continue
        _check_reference(check, node, port_name, name, port.types, available)
    return frozenset(written)


def _check_reference(
    check: Check,
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
    wrong = [w for w in writers if not fits_any(w.types, types)]
    if wrong:
        check.add(
            ERROR,
            node,
            f"{port!r} of {node.label!r} needs {type_names(types)}, but "
            f"{name} is {type_names(wrong[0].types)} (from {wrong[0].label}).",
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
