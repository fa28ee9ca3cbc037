"""The words a cell uses for its faults, and the error type each one gives a failed node.

The simulated and the UR cell finish a command that a fault ended with a message naming the
fault ("move_linear: protective stop"); :func:`fault_error` turns that message into the
:class:`~engine.error_types.ErrorType` a Catch node matches, so both cells report a fault
the same way. The UR cell's ``fault_reason`` builds its words from these constants.
"""

from __future__ import annotations

from engine.error_types import ErrorType

__all__ = ["CONNECTION_LOST", "EMERGENCY_STOP", "PROTECTIVE_STOP", "fault_error"]

PROTECTIVE_STOP = "protective stop"
EMERGENCY_STOP = "emergency stop"
CONNECTION_LOST = "connection lost"

_BY_WORDS: tuple[tuple[str, ErrorType], ...] = (
    (PROTECTIVE_STOP, ErrorType.PROTECTIVE_STOP),
    (EMERGENCY_STOP, ErrorType.EMERGENCY_STOP),
    (CONNECTION_LOST, ErrorType.CONNECTION_LOST),
)


def fault_error(message: str) -> ErrorType:
    """The error type of a command's failure message: a fault it names, else ``failed``."""
    text = message.lower()
    for words, error in _BY_WORDS:
        if words in text:
            return error
    return ErrorType.FAILED
