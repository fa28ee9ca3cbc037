"""Errors of the UR cell."""

from __future__ import annotations

import logging

from capabilities.errors import CapabilityError

__all__ = ["URError", "URConnectionLost", "ur_words"]


class URError(CapabilityError):
    """A UR controller refused or could not do what was asked."""


class URConnectionLost(URError):
    """The connection to the UR controller is gone."""


# What ur_rtde and its controller say (the text of its exceptions), in this project's words.
# Checked in order, lower case; the first match wins.
_WORDS: tuple[tuple[str, str], ...] = (
    (
        "enable remote control",
        "the robot is in local control: switch it to remote control on the pendant",
    ),
    (
        "timeout connecting to ur dashboard",
        "the controller's dashboard does not answer: is the robot on, and is this its address?",
    ),
    (
        "could not connect to",
        "nothing answers at the controller's address: is the robot on, and is this its address?",
    ),
    (
        "connection refused",
        "the controller refused the connection: is the robot on, and is this its address?",
    ),
    (
        "failed to start control script",
        "the controller did not start the control script "
        "within 5 s: is the arm powered on, brakes released, in remote control?",
    ),
    ("rtde data synchronization", "the controller did not start sending its state"),
    ("control program is not running", "the control script is not running on the controller"),
    (
        "cannot unlock protective stop until",
        "not yet: a protective stop can be unlocked only "
        "some seconds after it happened (5 s on a UR)",
    ),
    ("failed to execute: stop", "the controller would not stop the program it was running"),
    ("end of file", "the controller closed the connection"),
    ("connection reset", "the controller closed the connection"),
    ("broken pipe", "the controller closed the connection"),
    ("timed out", "the controller did not answer in time"),
    ("timeout", "the controller did not answer in time"),
    ("unable to get state data", "the controller does not send a value the robot's driver needs"),
)


def ur_words(exc: BaseException) -> str:
    """What went wrong in a ur_rtde call, in words a user of the cell reads (never ur_rtde's
    own text: that goes to the log). Errors of this package keep their words.
    """
    if isinstance(exc, URError):
        return str(exc)
    logging.getLogger(__name__).info("ur_rtde said: %s: %s", type(exc).__name__, exc)
    text = str(exc).lower()
    for needle, words in _WORDS:
        if needle in text:
            return words
    return f"the robot's driver failed ({type(exc).__name__}); the log has its words"
