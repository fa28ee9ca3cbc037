"""The words a cell uses for its faults, and the error type each one gives a failed node.

The simulated and the UR cell finish a command that a fault ended with a message naming the
fault ("move_linear: protective stop"); :func:`fault_error` turns that message into the
:class:`~engine.error_types.ErrorType` a Catch node matches, so both cells report a fault
the same way. The UR cell's ``fault_reason`` builds its words from these constants.

A cell that can stop on its own has ``hold_reason()`` (why it cannot act, in these words; ""
when it can); :func:`hold_check` makes the executor's hold check of it (``engine.hold``), so
the CLI and the Instructor wire every cell the same way (``capabilities.cell_features``
declares it and the other optional features of a cell as typed protocols).
"""

from __future__ import annotations

from capabilities.cell_features import HoldsRuns
from engine.error_types import ErrorType
from engine.hold import Hold, HoldCheck

__all__ = [
    "CONNECTION_LOST",
    "EMERGENCY_STOP",
    "LOOKING",
    "PROTECTIVE_STOP",
    "fault_error",
    "hold_check",
]

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


# Capabilities that only look (the cameras): a stop of the arm leaves their operations
# running, so a watch for the next part goes on while the arm stands and recovers.
LOOKING = frozenset({"occupancy", "markers", "perception"})


def hold_check(cell: object) -> HoldCheck | None:
    """The executor's hold check of a cell that holds runs (None for one that does not);
    its stops spare the operations of the capabilities that only look.
    """
    if not isinstance(cell, HoldsRuns):
        return None
    ask = cell.hold_reason

    def check() -> Hold | None:
        reason = ask()
        return Hold(reason, fault_error(reason), LOOKING) if reason else None

    return check
