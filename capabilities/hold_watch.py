"""How ``costar run`` follows the holds of its cell: it says each one, and gives up on one that
lasts too long.

A cell holds the run while it cannot act (a protective stop, a dead control script, a lost
controller). A person at the Instructor sees it and clears it; a run from the command line may
have nobody there, so past ``--hold-timeout`` it ends (exit 3) saying why it was held and what
the cell last knew of its robot.
"""

from __future__ import annotations

import time
from typing import TextIO

from capabilities.cell_features import ReportsStatus
from engine.events import Event, RunHeld

__all__ = ["DEFAULT_HOLD_TIMEOUT", "HoldWatch"]

DEFAULT_HOLD_TIMEOUT = 600.0  # s: ten minutes for a person to come and clear it


class HoldWatch:
    """A run's listener that prints its holds and times the one under way.

    Args:
        out: where the lines go.
        timeout: seconds a single hold may last before :meth:`expired` says so.
        cell: the run's cell; its ``status()`` (when it reports one) names the robot's last state.
    """

    def __init__(self, out: TextIO, timeout: float = DEFAULT_HOLD_TIMEOUT, cell: object = None):
        self._out = out
        self._timeout = timeout
        self._cell = cell
        self.reason = ""
        self._since: float | None = None

    def __call__(self, event: Event) -> None:
        if not isinstance(event, RunHeld):
            return
        if event.reason and self._since is None:
            self._since = time.monotonic()
        elif not event.reason:
            self._since = None
        self.reason = event.reason
        text = (
            f"held: {event.reason}{self._controller_says(event.reason)} (the run goes on once "
            f"the robot is ready; gives up after {self._timeout:g} s; Ctrl-C stops it)"
            if event.reason
            else "the robot is ready: the run goes on"
        )
        print(f"tick {event.tick:>5}  {text}", file=self._out, flush=True)

    def _controller_says(self, reason: str) -> str:
        """What the robot's controller reports with the hold: its safety mode and how the
        operator clears it ("; safety mode PROTECTIVE_STOP, clear it on the pendant ...").
        """
        robot = self._cell.status() if isinstance(self._cell, ReportsStatus) else None
        if robot is None or not robot.connected or robot.problem != reason:
            return ""
        return f"; safety mode {robot.safety_mode}" + (f", {robot.hint}" if robot.hint else "")

    def expired(self) -> bool:
        """True once the hold under way has lasted longer than the timeout."""
        since = self._since
        return since is not None and time.monotonic() - since > self._timeout

    def give_up(self) -> str:
        """The line that says why the run ends: the hold, how long, the robot's last state."""
        held = time.monotonic() - (self._since or time.monotonic())
        line = f"gave up after {held:.0f} s held: {self.reason}"
        robot = self._cell.status() if isinstance(self._cell, ReportsStatus) else None
        if robot is not None:
            line += (
                f"; the robot: robot mode {robot.robot_mode}, safety mode {robot.safety_mode}, "
                f"program {robot.program}"
            )
            if robot.problem and robot.problem != self.reason:
                line += f" ({robot.problem})"
        return line
