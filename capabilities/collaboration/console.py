"""OperatorConsole: where the running plan meets the people at the cell.

The plan asks questions (``ask`` -> a :class:`Prompt` the Instructor shows with Yes/No) and
waits for buttons (a button in the Instructor, or on the real cell a digital input such as
the paper's foot pedal). The console knows no Qt: it is called from the engine's thread, a
worker thread, the GUI thread or a digital-input poller, and tells its listeners what
changed from whichever thread made the change (the GUI marshals them to its own thread).

Each answer and press says who gave it (``by``: "the Instructor", "--confirm yes", "the
terminal", "digital input"...), so that a run's record keeps who did what, and when.

Buttons latch: a press is remembered until an operation consumes it; several presses before
the next consume count as one (a bounced pedal or a double click must not skip a step).
"""

from __future__ import annotations

import enum
import itertools
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass

from capabilities.collaboration.errors import CollaborationError

__all__ = [
    "ConsoleEvent",
    "ConsoleEventKind",
    "ConsoleListener",
    "OperatorConsole",
    "Prompt",
    "PromptState",
]

_log = logging.getLogger(__name__)


class PromptState(str, enum.Enum):
    """Where a prompt is in its life: open, answered yes or no, or withdrawn."""

    PENDING = "pending"
    YES = "yes"
    NO = "no"
    CANCELLED = "cancelled"


class Prompt:
    """A question to the operator; answered once, from any thread.

    Attributes:
        id: unique within its console ("p1", "p2", ...).
        text: the question as shown.
        source: who asks (a node's name), shown under the question.
        number: the order of asking within its console (1, 2, ...): listeners on several
            threads may hear of prompts in another order.
    """

    def __init__(self, prompt_id: str, text: str, source: str = "", number: int = 0) -> None:
        self.id = prompt_id
        self.number = number
        self.text = text
        self.source = source
        self._lock = threading.Lock()
        self._state = PromptState.PENDING
        self._reason = ""
        self._by = ""
        self._done = threading.Event()
        self._callbacks: list[Callable[[Prompt], None]] = []

    @property
    def state(self) -> PromptState:
        return self._state

    @property
    def answer(self) -> bool | None:
        """True (yes), False (no), None (not answered: pending or withdrawn)."""
        state = self._state
        return (
            None
            if state in (PromptState.PENDING, PromptState.CANCELLED)
            else state is PromptState.YES
        )

    @property
    def reason(self) -> str:
        """Why a withdrawn prompt was withdrawn ("halted", "timed out")."""
        return self._reason

    @property
    def answered_by(self) -> str:
        """Who answered or withdrew it ("" when nobody said)."""
        return self._by

    @property
    def closed(self) -> bool:
        return self._state is not PromptState.PENDING

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the prompt is closed; False when ``timeout`` (wall seconds) passed."""
        return self._done.wait(timeout)

    def add_done_callback(self, fn: Callable[[Prompt], None]) -> None:
        """Call ``fn(prompt)`` once it closes (at once, here, if it already has)."""
        with self._lock:
            if self._state is PromptState.PENDING:
                self._callbacks.append(fn)
                return
        fn(self)

    def _close(self, state: PromptState, reason: str, by: str = "") -> bool:
        with self._lock:
            if self._state is not PromptState.PENDING:
                return False
            self._state, self._reason, self._by = state, reason, by
            callbacks, self._callbacks = self._callbacks, []
        self._done.set()
        for fn in callbacks:
            _call_safely(fn, self)
        return True

    def __repr__(self) -> str:
        return f"Prompt({self.id!r}, {self.text!r}, {self._state.value})"


class ConsoleEventKind(str, enum.Enum):
    """What happened at the console: a prompt shown or closed, a button pressed."""

    PROMPT_SHOWN = "prompt_shown"
    PROMPT_CLOSED = "prompt_closed"
    BUTTON_PRESSED = "button_pressed"


@dataclass(frozen=True)
class ConsoleEvent:
    """What a listener hears: a prompt shown or closed, or a button pressed (``by`` whom)."""

    kind: ConsoleEventKind
    prompt: Prompt | None = None
    button: str = ""
    by: str = ""


ConsoleListener = Callable[[ConsoleEvent], None]


def _call_safely(fn: Callable[..., object], *args: object) -> None:
    try:
        fn(*args)
    except Exception:  # a listener's bug must not break the plan that told it
        _log.exception("operator console callback %r raised", fn)


class OperatorConsole:
    """Named buttons, yes/no prompts and listeners; safe to use from any thread.

    Args:
        buttons: the buttons the operator has (the GUI shows these; ``press`` accepts any
            name, so a digital input can add its own).
    """

    def __init__(self, buttons: tuple[str, ...] = ("continue",)) -> None:
        self.buttons = tuple(buttons)
        self._lock = threading.Lock()
        self._ids = itertools.count(1)
        self._prompts: dict[str, Prompt] = {}
        self._latched: dict[str, int] = {}
        self._presses: dict[str, int] = {}
        self._listeners: list[ConsoleListener] = []

    # ------------------------------------------------------------------ listeners

    def add_listener(self, fn: ConsoleListener) -> None:
        """Call ``fn(event)`` on every change, from the thread that made it."""
        with self._lock:
            self._listeners.append(fn)

    def remove_listener(self, fn: ConsoleListener) -> None:
        """Stop calling ``fn``; unknown listeners are ignored."""
        with self._lock:
            if fn in self._listeners:
                self._listeners.remove(fn)

    def _notify(self, event: ConsoleEvent) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for fn in listeners:
            _call_safely(fn, event)

    # ------------------------------------------------------------------ buttons

    def press(self, name: str = "continue", by: str = "") -> None:
        """The operator pressed a button (GUI thread, digital-input poller, tests); ``by``:
        where the press came from.
        """
        with self._lock:
            self._latched[name] = self._latched.get(name, 0) + 1
            self._presses[name] = self._presses.get(name, 0) + 1
        self._notify(ConsoleEvent(ConsoleEventKind.BUTTON_PRESSED, button=name, by=by))

    def consume(self, name: str = "continue") -> bool:
        """True if the button was pressed since the last consume; clears the latch."""
        with self._lock:
            return self._latched.pop(name, 0) > 0

    def clear(self, name: str = "continue") -> None:
        """Forget a latched press (an operation that wants only presses from now on)."""
        with self._lock:
            self._latched.pop(name, None)

    def presses(self, name: str = "continue") -> int:
        """How many times the button was pressed since the console was made."""
        with self._lock:
            return self._presses.get(name, 0)

    # ------------------------------------------------------------------ prompts

    def ask(self, text: str, source: str = "") -> Prompt:
        """Show a yes/no question; the returned prompt closes when answered or cancelled.

        Raises:
            CollaborationError: the question is empty.
        """
        if not text.strip():
            raise CollaborationError("a question for the operator needs text")
        with self._lock:
            number = next(self._ids)
            prompt = Prompt(f"p{number}", text, source, number)
            self._prompts[prompt.id] = prompt
        self._notify(ConsoleEvent(ConsoleEventKind.PROMPT_SHOWN, prompt))
        return prompt

    def answer(self, prompt_id: str, yes: bool, by: str = "") -> bool:
        """Answer an open prompt (``by``: who answered); False when it is unknown or
        already closed.
        """
        state = PromptState.YES if yes else PromptState.NO
        return self._close(prompt_id, state, "answered", by)

    def cancel(self, prompt_id: str, reason: str = "withdrawn") -> bool:
        """Withdraw an open prompt (the plan stopped waiting); False when already closed."""
        return self._close(prompt_id, PromptState.CANCELLED, reason)

    def pending(self) -> list[Prompt]:
        """The open prompts, oldest first."""
        with self._lock:
            return list(self._prompts.values())

    def prompt(self, prompt_id: str) -> Prompt | None:
        """An open prompt by id, or None."""
        with self._lock:
            return self._prompts.get(prompt_id)

    def _close(self, prompt_id: str, state: PromptState, reason: str, by: str = "") -> bool:
        with self._lock:
            prompt = self._prompts.pop(prompt_id, None)
        if prompt is None or not prompt._close(state, reason, by):
            return False
        self._notify(ConsoleEvent(ConsoleEventKind.PROMPT_CLOSED, prompt, by=by))
        return True
