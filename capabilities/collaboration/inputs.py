"""Digital inputs as operator buttons: the paper's foot pedal on a UR digital input.

A :class:`DigitalInputSource` reads one input (the UR backend will read RTDE's digital
inputs; there is none yet). A :class:`DigitalInputButton` polls a source on its own thread
and presses a console button on each rising edge, so a plan cannot tell a pedal from the
Instructor's button. :class:`SimDigitalInput` is an input a test or the simulated cell sets.
"""

from __future__ import annotations

import threading
from typing import Protocol

from capabilities.collaboration.console import OperatorConsole

__all__ = ["DigitalInputButton", "DigitalInputSource", "SimDigitalInput"]


class DigitalInputSource(Protocol):
    """One digital input: ``read`` returns its level now and must not block long."""

    def read(self) -> bool: ...


class SimDigitalInput:
    """A digital input whose level is set by hand (tests, the simulated cell)."""

    def __init__(self) -> None:
        self._level = False

    def set(self, level: bool) -> None:
        self._level = bool(level)

    def read(self) -> bool:
        return self._level


class DigitalInputButton:
    """Presses ``button`` of ``console`` when ``source`` goes from low to high.

    Args:
        source: the input to watch.
        console: the console whose button it presses.
        button: the button's name.
        period: seconds between reads (wall clock: the input is a real signal).
    """

    def __init__(
        self,
        source: DigitalInputSource,
        console: OperatorConsole,
        button: str = "continue",
        period: float = 0.01,
    ) -> None:
        self._source = source
        self._console = console
        self._button = button
        self._period = period
        self._stop = threading.Event()
        self._last = False
        self._thread: threading.Thread | None = None

    def poll_once(self) -> bool:
        """Read the input once; True (and the button pressed) on a rising edge."""
        level = bool(self._source.read())
        rising = level and not self._last
        self._last = level
        if rising:
            self._console.press(self._button, "digital input")
        return rising

    def start(self) -> None:
        """Begin polling on a daemon thread (idempotent)."""
        if self._thread is not None:
            return
        self._last = bool(self._source.read())  # an input already high is not a press
        self._thread = threading.Thread(target=self._run, name="costar-pedal", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop polling and join the thread (idempotent)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run(self) -> None:
        while not self._stop.wait(self._period):
            self.poll_once()
