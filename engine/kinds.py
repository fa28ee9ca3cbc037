"""The manifests of the engine's own node kinds: the typed ports of logic nodes and decorators.

A logic node's settings (a Parallel's policy, a count, a timeout, the seconds of a Wait) are
ports like an operation's parameters, bound in ``NodeSpec.params`` to fixed values (as in
BehaviorTree.CPP, where a node's manifest lists its ports). This table is the one place their
types, defaults and docs live; validation, the builder and the inspector read it.

Ports of logic nodes take fixed values only: the tree is built from them once, so a
reference would be read at no defined moment. Validation says so when a file binds one.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from engine.error_types import parse_error_types
from engine.operations import PortSpec
from engine.script import ScriptSyntaxError, parse_script
from engine.spec import Binding, NodeKind
from engine.types import ParamType

__all__ = [
    "KIND_PORTS",
    "KIND_DOC",
    "POLICY_WORDS",
    "check_setting",
    "kind_port",
    "setting",
    "settings_of",
]

_N, _D, _T = ParamType.NUMBER, ParamType.DURATION, ParamType.TEXT
# A Parallel's policy: the words, or a count of children (a Number).
POLICY_WORDS: dict[str, tuple[str, ...]] = {"success": ("all", "any"), "failure": ("any",)}


def _count(name: str, doc: str, default: float | None = None) -> PortSpec:
    return PortSpec(name, (_N,), default=default, doc=doc)


def _seconds(name: str, doc: str, default: float | None = None) -> PortSpec:
    return PortSpec(name, (_D,), default=default, unit="s", doc=doc)


def _words(name: str, default: str, doc: str, *words: str) -> PortSpec:
    """A port that takes one of a few words (BehaviorTree.CPP's bool or NodeStatus)."""
    return PortSpec(name, (_T,), default=default, doc=doc, choices=words)


def _text(name: str, doc: str, default: str | None = None) -> PortSpec:
    return PortSpec(name, (_T,), default=default, doc=doc)


_ENTRY = " ({key} reads the entry key)"
_BOOL_WORDS = ("true", "false")
_SWITCH_CASES = 6  # Switch2 .. Switch6


def _policy(name: str, default: str, doc: str) -> PortSpec:
    """A Parallel's policy port: a word of ``POLICY_WORDS[name]`` or a count."""
    return PortSpec(name, (_T, _N), default=default, doc=doc, choices=POLICY_WORDS[name])


KIND_PORTS: dict[NodeKind, tuple[PortSpec, ...]] = {
    NodeKind.PARALLEL: (
        _policy("success", "all", "succeed when all, any, or this many children succeeded"),
        _policy("failure", "any", "fail when any, or this many children failed"),
    ),
    NodeKind.CATCH: (
        PortSpec(
            "errors",
            (_T,),
            default="any",
            doc="the error types the handler takes: a comma-separated list, or any",
        ),
        PortSpec(
            "error",
            (_T,),
            default="",
            doc="the name of the parameter that receives the caught error as "
            "'type: message' (empty: not kept)",
        ),
    ),
    NodeKind.ITERATOR: (
        _count("count", "stop with SUCCESS after this many successes (0: no limit)", 0.0),
        _seconds("timeout", "stop with SUCCESS after this many seconds (0: no limit)", 0.0),
    ),
    NodeKind.ENFORCE: (
        _count("count", "give up with FAILURE after this many failures (0: no limit)", 0.0),
        _seconds("timeout", "give up with FAILURE after this many seconds (0: no limit)", 0.0),
    ),
    NodeKind.REPEAT: (_count("count", "how many times (-1: with no limit)"),),
    NodeKind.RETRY: (_count("count", "how many attempts (-1: with no limit)"),),
    NodeKind.TIMEOUT: (_seconds("seconds", "time limit"),),
    NodeKind.WAIT: (_seconds("seconds", "how long to wait"),),
    NodeKind.SCRIPT: (
        PortSpec("code", (_T,), doc="the script: statements of BehaviorTree.CPP's language"),
    ),
    NodeKind.SCRIPT_CONDITION: (
        PortSpec("code", (_T,), doc="the script; its last value, true or false, is the answer"),
    ),
    NodeKind.PARALLEL_ALL: (
        _count(
            "max_failures",
            "fail when at least this many children failed (negative: counted back from all)",
            1.0,
        ),
    ),
    NodeKind.SWITCH: (
        _text("variable", "the text compared with the cases" + _ENTRY),
        *(
            _text(f"case_{n}", f"the child {n} runs when the variable equals this" + _ENTRY, "")
            for n in range(1, _SWITCH_CASES + 1)
        ),
    ),
    NodeKind.TRY_CATCH: (
        _words(
            "catch_on_halt",
            "false",
            "run the catch child when the node is halted during the try block",
            *_BOOL_WORDS,
        ),
    ),
    NodeKind.DELAY: (_seconds("seconds", "how long to wait before the child starts"),),
    NodeKind.RUN_ONCE: (
        _words(
            "then_skip",
            "true",
            "after the first run, skip (true) or give the first result again (false)",
            *_BOOL_WORDS,
        ),
    ),
    NodeKind.PRECONDITION: (
        _text("if", "the script; the child runs when its value is true"),
        _words(
            "else",
            "FAILURE",
            "the status when the script is false",
            "FAILURE",
            "SUCCESS",
            "SKIPPED",
            "RUNNING",
        ),
    ),
    NodeKind.LOOP: (
        _text("queue", "the values, separated by ; (or {key}: an entry holding them)"),
        _text("value", "{key}: the entry each value is written to before the child runs"),
        _words("type", "string", "the type of the values", "int", "double", "bool", "string"),
        _words(
            "if_empty",
            "SUCCESS",
            "the status when no value is left",
            "SUCCESS",
            "FAILURE",
            "SKIPPED",
        ),
    ),
    NodeKind.SET_BLACKBOARD: (
        _text("value", "the value written; {key} copies the entry key"),
        _text("output_key", "the name of the entry written" + _ENTRY),
    ),
    NodeKind.UNSET_BLACKBOARD: (_text("key", "the name of the entry removed" + _ENTRY),),
    **{
        kind: (_text("entry", "the name of the entry watched (or {key})"),)
        for kind in (
            NodeKind.SKIP_UNLESS_UPDATED,
            NodeKind.WAIT_VALUE_UPDATE,
            NodeKind.WAS_ENTRY_UPDATED,
        )
    },
}
# The ports that hold a script.
_SCRIPT_PORTS = {
    (NodeKind.SCRIPT, "code"),
    (NodeKind.SCRIPT_CONDITION, "code"),
    (NodeKind.PRECONDITION, "if"),
}

# What a fixed value of each port must be beyond its type: (minimum, whole number).
_LIMITS: dict[tuple[NodeKind, str], tuple[float, bool]] = {
    (NodeKind.ITERATOR, "count"): (0, True),
    (NodeKind.ITERATOR, "timeout"): (0, False),
    (NodeKind.ENFORCE, "count"): (0, True),
    (NodeKind.ENFORCE, "timeout"): (0, False),
    (NodeKind.REPEAT, "count"): (1, True),
    (NodeKind.RETRY, "count"): (1, True),
    (NodeKind.WAIT, "seconds"): (0, False),
    (NodeKind.TIMEOUT, "seconds"): (0, False),
    (NodeKind.PARALLEL, "success"): (-math.inf, True),
    (NodeKind.PARALLEL, "failure"): (-math.inf, True),
    (NodeKind.PARALLEL_ALL, "max_failures"): (-math.inf, True),
    (NodeKind.DELAY, "seconds"): (0, False),
}
# Counts that may be negative (counted back from the number of children) but not 0.
_NONZERO = {(NodeKind.PARALLEL, "success"), (NodeKind.PARALLEL, "failure")}
# Counts whose -1 means no limit, as BehaviorTree.CPP's num_cycles and num_attempts.
_UNLIMITED = {(NodeKind.REPEAT, "count"), (NodeKind.RETRY, "count")}

KIND_DOC: dict[NodeKind, str] = {
    NodeKind.SEQUENCE: "Runs children in order; fails at the first failure.",
    NodeKind.SELECTOR: "Tries children in order until one succeeds (fallback).",
    NodeKind.PARALLEL: "Runs children at the same time; finishes by its success/failure policy.",
    NodeKind.REACTIVE_SEQUENCE: "A sequence that re-checks its conditions every tick and halts "
    "the running child when one turns false.",
    NodeKind.REACTIVE_SELECTOR: "A selector that re-checks its conditions every tick and switches "
    "to a higher-priority child when its condition holds.",
    NodeKind.CATCH: "Runs its first node; when that fails with a chosen error type, runs its "
    "second node (the handler) instead of failing.",
    NodeKind.ITERATOR: "Repeats its child while it succeeds.",
    NodeKind.ENFORCE: "Retries its child until it succeeds.",
    NodeKind.INVERTER: "Turns success into failure and back.",
    NodeKind.REPEAT: "Runs its child a number of times while it succeeds.",
    NodeKind.RETRY: "Tries its child up to a number of times until it succeeds.",
    NodeKind.TIMEOUT: "Fails, halting its child, when the child runs too long.",
    NodeKind.FORCE_SUCCESS: "Succeeds once its child has finished.",
    NodeKind.FORCE_FAILURE: "Fails once its child has finished.",
    NodeKind.WAIT: "Waits a number of seconds.",
    NodeKind.SCRIPT: "Runs a script that sets named parameters (BehaviorTree.CPP's Script).",
    NodeKind.SCRIPT_CONDITION: "Succeeds when a script's value is true, fails when it is false "
    "(BehaviorTree.CPP's ScriptCondition).",
    NodeKind.SEQUENCE_WITH_MEMORY: "A sequence that, run again after a failure, goes on from "
    "the child that failed, and lets a tick pass after each child that succeeded at once "
    "(BehaviorTree.CPP's SequenceWithMemory).",
    NodeKind.ASYNC_SEQUENCE: "A sequence that lets a tick pass after each child that succeeded "
    "at once (BehaviorTree.CPP's AsyncSequence).",
    NodeKind.ASYNC_FALLBACK: "A selector that lets a tick pass after each child that failed at "
    "once (BehaviorTree.CPP's AsyncFallback).",
    NodeKind.PARALLEL_ALL: "Runs all children to the end at the same time; fails when too many "
    "failed (BehaviorTree.CPP's ParallelAll).",
    NodeKind.IF_THEN_ELSE: "Runs its second node when its first succeeds, else its third "
    "(BehaviorTree.CPP's IfThenElse).",
    NodeKind.WHILE_DO_ELSE: "Checks its first node every tick: runs the second while it "
    "succeeds, the third when it fails (BehaviorTree.CPP's WhileDoElse).",
    NodeKind.SWITCH: "Runs the node of the case that equals the variable, else the last node "
    "(BehaviorTree.CPP's Switch2 to Switch6).",
    NodeKind.TRY_CATCH: "Runs its nodes in order; when one fails, runs the last node, then "
    "fails (BehaviorTree.CPP's TryCatch).",
    NodeKind.KEEP_RUNNING_UNTIL_FAILURE: "Runs its child again and again until it fails.",
    NodeKind.DELAY: "Waits a number of seconds, then runs its child.",
    NodeKind.RUN_ONCE: "Runs its child only the first time (BehaviorTree.CPP's RunOnce).",
    NodeKind.PRECONDITION: "Runs its child when a script is true (BehaviorTree.CPP's "
    "Precondition).",
    NodeKind.LOOP: "Runs its child once for each value of a queue, the value in a named "
    "parameter (BehaviorTree.CPP's LoopInt, LoopDouble, LoopBool, LoopString).",
    NodeKind.ALWAYS_SUCCESS: "Succeeds.",
    NodeKind.ALWAYS_FAILURE: "Fails.",
    NodeKind.SET_BLACKBOARD: "Sets a named parameter to a value (BehaviorTree.CPP's "
    "SetBlackboard).",
    NodeKind.UNSET_BLACKBOARD: "Removes a named parameter (BehaviorTree.CPP's UnsetBlackboard).",
    NodeKind.SKIP_UNLESS_UPDATED: "Runs its child when a named parameter was written since it "
    "last looked, else is skipped (BehaviorTree.CPP's SkipUnlessUpdated).",
    NodeKind.WAIT_VALUE_UPDATE: "Waits until a named parameter is written, then runs its "
    "child (BehaviorTree.CPP's WaitValueUpdate).",
    NodeKind.WAS_ENTRY_UPDATED: "Succeeds when a named parameter was written since it last "
    "looked (BehaviorTree.CPP's WasEntryUpdated).",
    NodeKind.OPERATION: "Runs a capability operation.",
}


def kind_port(kind: NodeKind, name: str) -> PortSpec | None:
    """The port ``name`` of a logic node kind, or None."""
    return next((p for p in KIND_PORTS.get(kind, ()) if p.name == name), None)


def setting(kind: NodeKind, name: str, value: str | float) -> Binding:
    """A fixed binding of a logic node's port: a word as Text, a number as the port's type.

    Raises:
        ValueError: ``value`` is neither a text nor a number.
    """
    if isinstance(value, str):
        return Binding.fixed(value, ParamType.TEXT)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"a setting is a number or a text, not {value!r}")
    port = kind_port(kind, name)
    return Binding.fixed(float(value), port.types[-1] if port is not None else ParamType.NUMBER)


def check_setting(kind: NodeKind, name: str, value: Any) -> str | None:
    """None when a fixed value of the right type is also in range, else what was expected."""
    if isinstance(value, str):
        if kind is NodeKind.CATCH and name == "errors":
            return _error_list_problem(value)
        if (kind, name) in _SCRIPT_PORTS:
            return _script_problem(value)
        return None  # a word: checked against the port's choices
    minimum, whole = _LIMITS.get((kind, name), (0.0, False))
    strict = kind is NodeKind.TIMEOUT  # a time limit of 0 would fail at once
    is_number = isinstance(value, (int, float)) and not isinstance(value, bool)
    nonzero = (kind, name) in _NONZERO
    if (kind, name) in _UNLIMITED and value == -1:
        return None
    if (
        is_number
        and (value > minimum if strict else value >= minimum)
        and (not whole or float(value).is_integer())
        and not (nonzero and value == 0)
    ):
        return None
    if nonzero:
        return "a whole number other than 0"
    if (kind, name) in _UNLIMITED:
        return f"a whole number of at least {minimum:g}, or -1 for no limit"
    if whole:
        return (
            "a whole number" if minimum == -math.inf else f"a whole number of at least {minimum:g}"
        )
    return "a number of seconds above 0" if strict else "a number of seconds, 0 or more"


def _error_list_problem(text: str) -> str | None:
    """None when ``text`` names error types (or "any"), else what was expected and why."""
    try:
        parse_error_types(text)
    except ValueError as exc:
        return f"a comma-separated list of error types, or any ({exc})"
    return None


def _script_problem(text: str) -> str | None:
    """None when ``text`` parses as a script, else what was expected where."""
    try:
        parse_script(text)
    except ScriptSyntaxError as exc:
        return f"a script in BehaviorTree.CPP's language ({exc})"
    return None


def settings_of(kind: NodeKind, params: Mapping[str, Binding]) -> dict[str, Any]:
    """The values of a logic node's ports: its fixed bindings, else the manifest's defaults.

    Args:
        kind: the node's kind.
        params: its bindings (checked by validation; the builder checks again with this).

    Raises:
        ValueError: a required port unbound, a reference, or a value out of range; the
            message says which port and what was expected.
    """
    ports = KIND_PORTS.get(kind, ())
    for name in params:
        if kind_port(kind, name) is None:
            allowed = ", ".join(p.name for p in ports) or "none"
            raise ValueError(f"{kind.value} has no setting {name!r} (settings: {allowed})")
    values: dict[str, Any] = {}
    for port in ports:
        binding = params.get(port.name)
        if binding is not None and binding.is_ref:
            raise ValueError(f"{port.name!r} takes a fixed value, not a reference")
        value = port.default if binding is None or binding.value is None else binding.value
        if value is None:
            raise ValueError(f"{kind.value} needs a value for {port.name!r} ({port.doc})")
        expected = check_setting(kind, port.name, value)
        if (
            expected is None
            and isinstance(value, str)
            and port.choices
            and value not in port.choices
        ):
            counts = " or a count" if ParamType.NUMBER in port.types else ""
            expected = f"one of {', '.join(port.choices)}{counts}"
        if expected is not None:
            shown = f"{value:g}" if isinstance(value, float) else repr(value)
            raise ValueError(f"{port.name!r} must be {expected}, not {shown}")
        values[port.name] = value
    return values
