"""Settings of the logic node kinds: what each kind's ``config`` may hold.

One table serves validation, file reading, the builder and the Instructor's inspector, so a
setting is described once.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from engine.spec import NodeKind

__all__ = ["ConfigField", "KIND_CONFIG", "KIND_DOC", "check_config"]


@dataclass(frozen=True)
class ConfigField:
    """One setting of a logic node.

    Attributes:
        name: key in ``NodeSpec.config``.
        kind: "count" (int >= 1), "seconds" (number > 0, or >= 0 for Wait), "policy_success"
            ("all", "any" or a count), "policy_failure" ("any" or a count).
        required: must be present.
        default: used when absent (None: off).
        doc: one line for the inspector.
    """

    name: str
    kind: str
    required: bool = False
    default: Any = None
    doc: str = ""


KIND_CONFIG: dict[NodeKind, tuple[ConfigField, ...]] = {
    NodeKind.PARALLEL: (
        ConfigField(
            "success",
            "policy_success",
            default="all",
            doc="succeed when all, any, or this many children succeeded",
        ),
        ConfigField(
            "failure",
            "policy_failure",
            default="any",
            doc="fail when any, or this many children failed",
        ),
    ),
    NodeKind.ITERATOR: (
        ConfigField("count", "count", doc="stop with SUCCESS after this many successes"),
        ConfigField("timeout", "seconds", doc="stop with SUCCESS after this many seconds"),
    ),
    NodeKind.ENFORCE: (
        ConfigField("count", "count", doc="give up with FAILURE after this many failures"),
        ConfigField("timeout", "seconds", doc="give up with FAILURE after this many seconds"),
    ),
    NodeKind.REPEAT: (ConfigField("count", "count", required=True, doc="how many times"),),
    NodeKind.RETRY: (ConfigField("count", "count", required=True, doc="how many attempts"),),
    NodeKind.TIMEOUT: (ConfigField("seconds", "seconds", required=True, doc="time limit"),),
    NodeKind.WAIT: (ConfigField("seconds", "wait_seconds", required=True, doc="how long to wait"),),
}

KIND_DOC: dict[NodeKind, str] = {
    NodeKind.SEQUENCE: "Runs children in order; fails at the first failure.",
    NodeKind.SELECTOR: "Tries children in order until one succeeds (fallback).",
    NodeKind.PARALLEL: "Runs children at the same time; finishes by its success/failure policy.",
    NodeKind.REACTIVE_SEQUENCE: "A sequence that re-checks its conditions every tick and halts "
    "the running child when one turns false.",
    NodeKind.REACTIVE_SELECTOR: "A selector that re-checks its conditions every tick and switches "
    "to a higher-priority child when its condition holds.",
    NodeKind.ITERATOR: "Repeats its child while it succeeds.",
    NodeKind.ENFORCE: "Retries its child until it succeeds.",
    NodeKind.INVERTER: "Turns success into failure and back.",
    NodeKind.REPEAT: "Runs its child a number of times while it succeeds.",
    NodeKind.RETRY: "Tries its child up to a number of times until it succeeds.",
    NodeKind.TIMEOUT: "Fails, halting its child, when the child runs too long.",
    NodeKind.FORCE_SUCCESS: "Succeeds once its child has finished.",
    NodeKind.FORCE_FAILURE: "Fails once its child has finished.",
    NodeKind.WAIT: "Waits a number of seconds.",
    NodeKind.OPERATION: "Runs a capability operation.",
}


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_field(spec: ConfigField, value: Any) -> str | None:
    """None when ``value`` fits, else what was expected."""
    is_count = isinstance(value, int) and not isinstance(value, bool) and value >= 1
    if spec.kind == "count":
        return None if is_count else "a whole number of at least 1"
    if spec.kind == "seconds":
        return None if _is_number(value) and value > 0 else "a number of seconds above 0"
    if spec.kind == "wait_seconds":
        return None if _is_number(value) and value >= 0 else "a number of seconds, 0 or more"
    if spec.kind == "policy_success":
        return (
            None if value in ("all", "any") or is_count else "'all', 'any' or a count of at least 1"
        )
    if spec.kind == "policy_failure":
        return None if value == "any" or is_count else "'any' or a count of at least 1"
    return f"a value of unknown setting kind {spec.kind}"


def check_config(kind: NodeKind, config: dict[str, Any]) -> list[tuple[str, str]]:
    """Problems with a node's settings as (setting name, sentence); empty when fine."""
    fields = {f.name: f for f in KIND_CONFIG.get(kind, ())}
    problems: list[tuple[str, str]] = []
    for name in config:
        if name not in fields:
            allowed = ", ".join(fields) or "none"
            problems.append((name, f"{kind.value} has no setting {name!r} (settings: {allowed})"))
    for name, spec in fields.items():
        if name not in config or config[name] is None:
            if spec.required:
                problems.append((name, f"{kind.value} needs the setting {name!r} ({spec.doc})"))
            continue
        expected = _check_field(spec, config[name])
        if expected is not None:
            problems.append((name, f"setting {name!r} must be {expected}, not {config[name]!r}"))
    return problems
