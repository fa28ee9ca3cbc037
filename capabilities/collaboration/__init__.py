"""The ``collaboration`` capability: the paper's Collaborator (section IV-B).

People and the robot share the cell: the plan asks the operator to confirm a step, waits for
an operator button (the Instructor's button, or a foot pedal on a digital input), and waits
until a person hands an object over by putting it down in a region (seen by its markers).
The meeting point of plan and people is the cell's ``operator`` interface, an
:class:`OperatorConsole`.
"""

from __future__ import annotations

from capabilities.collaboration.console import (
    ConsoleEvent,
    ConsoleEventKind,
    OperatorConsole,
    Prompt,
    PromptState,
)
from capabilities.collaboration.errors import CollaborationError
from capabilities.collaboration.operations import capability

__all__ = [
    "CollaborationError",
    "ConsoleEvent",
    "ConsoleEventKind",
    "OperatorConsole",
    "Prompt",
    "PromptState",
    "capability",
]
