"""The closed set of error types a node's FAILURE carries (Intera's Throw/Catch).

A failure says *why* in words (the node's message) and *what kind* of failure it is in one
of these types, which a Catch node matches. Operations name the type they know
(``Job.failed(message, error=ErrorType.NOT_FOUND)``); an unexpected exception is ``error``;
a node that fails without naming one takes the type of its failed child, else ``failed``.
"""

from __future__ import annotations

import enum

__all__ = ["ErrorType", "parse_error_types"]


class ErrorType(str, enum.Enum):
    """Why a node failed, as a Catch node can match it."""

    GRASP_FAILED = "grasp_failed"
    OBJECT_LOST = "object_lost"
    NOT_FOUND = "not_found"
    OCCLUDED = "occluded"  # a look found nothing because something (the arm) hid the view
    PROTECTIVE_STOP = "protective_stop"
    EMERGENCY_STOP = "emergency_stop"
    TIMEOUT = "timeout"
    CONNECTION_LOST = "connection_lost"
    COLLISION = "collision"
    INVALID_INPUT = "invalid_input"
    HALTED = "halted"
    ERROR = "error"  # an unexpected exception in an operation
    FAILED = "failed"  # a failure that names no type


ANY = "any"


def parse_error_types(text: str) -> frozenset[ErrorType] | None:
    """The types named by a comma-separated list; None for "any" (every type).

    Raises:
        ValueError: an empty list or a word that is not an error type, naming the choices.
    """
    words = [w.strip().lower() for w in text.split(",") if w.strip()]
    if words == [ANY]:
        return None
    if not words:
        raise ValueError("name at least one error type, or 'any'")
    known = {t.value: t for t in ErrorType}
    unknown = [w for w in words if w not in known]
    if unknown:
        raise ValueError(
            f"unknown error type {', '.join(map(repr, unknown))} (choices: any, {', '.join(known)})"
        )
    return frozenset(known[w] for w in words)
