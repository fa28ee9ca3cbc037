"""The robot's state in the status bar: connection, robot mode, safety mode, program, live.

A real cell (``capabilities.ur.cell.URCellSession``) keeps a snapshot of what its controller
reports, refreshed on its own I/O thread; this widget reads that snapshot on a timer, so the
GUI thread never waits on the robot. A cell without a robot controller (none) has no
``status()``, and the simulated cell answers None while its arm can move: the widget hides.
Next to it, the cell's clear button does the operator's clear of the problem shown
(``cell.clear()``) when the cell names one (``CellStatus.clear_action``: "Restart control
script" or "Unlock protective stop" on a UR, "Unlock protective stop" on the simulated cell
once the delay has passed). While the clear is not yet allowed (a UR refuses to unlock a
protective stop in the first 5 s) the button is shown greyed with the seconds left.
"""

from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QLabel, QToolButton, QWidget

from capabilities.cell_features import CellStatus, ClearsStop, ReportsStatus
from instructor_app.idle_timer import IdlePollTimer
from instructor_app.runtime.session import CellSession

__all__ = ["CellClearButton", "RobotStatusLabel"]

# After IDLE_READS reads in a row that changed nothing, the snapshot is read only every
# IDLE_INTERVAL_MS (a read that finds a change makes it quick again): an idle app wakes less.
IDLE_READS = 20
IDLE_INTERVAL_MS = 500
_OK_STYLE = "QLabel { background: #d8f0d8; color: #104010; padding: 2px 6px; }"
_FAULT_STYLE = "QLabel { background: #f6d0d0; color: #601010; padding: 2px 6px; }"


class RobotStatusLabel(QLabel):
    """Shows the open cell's robot state, refreshed every ``interval_ms``.

    Args:
        session: the cell session (the open cell may change under it).
        interval_ms: how often the snapshot is read (``IDLE_INTERVAL_MS`` while it does not
            change, if that is longer).

    Signals:
        presence_changed(bool): the open cell has (or no longer has) a robot controller; a
            window shows or hides the label on it.
        fault_changed(str): the problem shown changed ("" when the robot can move).
        clear_action_changed(str): the operator's clear offered changed ("" for none).
        clear_changed(str, int): the clear offered or the seconds before it is allowed
            changed.
    """

    presence_changed = Signal(bool)
    fault_changed = Signal(str)
    clear_action_changed = Signal(str)
    clear_changed = Signal(str, int)

    def __init__(
        self, session: CellSession, interval_ms: int = 100, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.setObjectName("RobotStatus")
        self._session = session
        self._shown: CellStatus | None = None
        self._timer = IdlePollTimer(interval_ms, IDLE_INTERVAL_MS, IDLE_READS, self)
        self._timer.timeout.connect(self.refresh)
        self._timer.start()
        session.cell_changed.connect(lambda _name: self.refresh())
        self.refresh()

    def refresh(self) -> None:
        """Read the cell's status snapshot and show it (only when it changed)."""
        cell = self._session.cell
        status = cell.status() if isinstance(cell, ReportsStatus) else None
        self._timer.polled(status != self._shown)
        if status == self._shown:
            return
        if (status is None) != (self._shown is None):
            self.presence_changed.emit(status is not None)
        fault_before, action_before, wait_before = self.fault, self.clear_action, self.clear_wait
        self._shown = status
        if self.fault != fault_before:
            self.fault_changed.emit(self.fault)
        if self.clear_action != action_before:
            self.clear_action_changed.emit(self.clear_action)
        if (self.clear_action, self.clear_wait) != (action_before, wait_before):
            self.clear_changed.emit(self.clear_action, self.clear_wait)
        if status is None:
            self.setText("")
            return
        if not status.connected:
            self.setText(f"Robot: {status.problem}")
        else:
            text = (
                f"Robot: {status.robot_mode} · safety {status.safety_mode} · "
                f"program {status.program}"
            )
            problem = status.problem + (f", {status.hint}" if status.hint else "")
            self.setText(text + (f" — {problem}" if problem else ""))
        self.setStyleSheet(_FAULT_STYLE if status.problem else _OK_STYLE)
        self.setToolTip(
            "What the robot's controller reports: connection, robot mode, safety mode and "
            "the control program. " + (f"Stopped: {status.problem}." if status.problem else "")
        )

    @property
    def interval_ms(self) -> int:
        """How often the status is read now."""
        return self._timer.interval()

    @property
    def present(self) -> bool:
        """Whether the open cell has a robot controller to show."""
        return self._shown is not None

    @property
    def fault(self) -> str:
        """The problem shown now ("" when the robot can move or there is no robot)."""
        return self._shown.problem if self._shown is not None else ""

    @property
    def clear_action(self) -> str:
        """The operator's clear the cell offers now ("" for none)."""
        return self._shown.clear_action if self._shown is not None else ""

    @property
    def clear_wait(self) -> int:
        """Whole seconds before that clear is allowed (0: now, or no clear offered)."""
        return self._shown.clear_wait if self._shown is not None else 0

    @property
    def hint(self) -> str:
        """How the operator clears the problem shown ("" when nothing is to be said)."""
        return self._shown.hint if self._shown is not None else ""


class CellClearButton(QToolButton):
    """The operator's clear of the robot's problem, labelled as the cell names it ("Restart
    control script", "Unlock protective stop"). Shown only while the cell offers one, and
    greyed with the seconds left ("Unlock protective stop (4 s)") until it is allowed; the
    cell does the work on its own thread, so the click returns at once and a held run goes on
    when the robot is ready.
    """

    def __init__(
        self, session: CellSession, status: RobotStatusLabel, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.setObjectName("CellClear")
        self.setToolTip("Clear the robot's stop; a held run then goes on")
        self._session = session
        self.setVisible(False)
        status.clear_changed.connect(self._on_action)
        self.clicked.connect(self._clear)

    def _on_action(self, action: str, wait: int = 0) -> None:
        self.setText(f"{action} ({wait} s)" if action and wait else action)
        self.setEnabled(not wait)
        self.setVisible(bool(action))

    def _clear(self) -> None:
        cell = self._session.cell
        if isinstance(cell, ClearsStop):
            cell.clear()
