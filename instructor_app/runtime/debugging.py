"""The operator's breakpoints, skipped nodes and forced results, by plan node id.

They belong to the Instructor's session, not to the plan file (a breakpoint is a look at a
run, not part of the task): they stay across runs and plan edits and are dropped with the
nodes they were on; the breakpoints are also kept in the settings by plan id, so that the
plan opened again has them (skips and forced results are not kept). Each run gets an
:class:`~engine.debugger.Debugger` made from them (:meth:`RunDebugging.debugger`); a change
while a run goes reaches that run at once. A forced result is given once: to the run going
on, else to the next run.
"""

from __future__ import annotations

from PySide6.QtCore import QObject, Signal

from engine.debugger import Breakpoint, Debugger, Forced
from engine.status import SUCCESS

__all__ = ["RunDebugging"]


class RunDebugging(QObject):
    """Breakpoints, skips and forced results of the plan's nodes.

    Signals:
        changed(): a breakpoint, skip or forced result was set or cleared (marks to redraw).
    """

    changed = Signal()

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._breakpoints: set[str] = set()
        self._skipped: set[str] = set()
        self._forced: dict[str, Forced] = {}
        self._live: Debugger | None = None  # the debugger of the run going on

    # ------------------------------------------------------------------ reading

    def has_breakpoint(self, node_id: str) -> bool:
        return node_id in self._breakpoints

    @property
    def breakpoints(self) -> frozenset[str]:
        return frozenset(self._breakpoints)

    def is_skipped(self, node_id: str) -> bool:
        return node_id in self._skipped

    def forced(self, node_id: str) -> Forced | None:
        return self._forced.get(node_id)

    def note(self, node_id: str) -> str:
        """What the node shows of them: "skipped", "forced: succeed", "forced: grasp_failed"."""
        if node_id in self._skipped:
            return "skipped"
        forced = self._forced.get(node_id)
        if forced is None:
            return ""
        if forced.status is SUCCESS:
            return "forced: succeed"
        return f"forced: {forced.error.value if forced.error else 'fail'}"

    def marked(self) -> set[str]:
        """Every node with a breakpoint, a skip or a forced result."""
        return {*self._breakpoints, *self._skipped, *self._forced}

    # ------------------------------------------------------------------ changing

    def toggle_breakpoint(self, node_id: str) -> bool:
        """Set or clear the breakpoint before ``node_id``; True when it is set now."""
        on = node_id not in self._breakpoints
        if on:
            self._breakpoints.add(node_id)
            if self._live is not None:
                self._live.set_breakpoint(Breakpoint(node_id))
        else:
            self._breakpoints.discard(node_id)
            if self._live is not None:
                self._live.clear_breakpoint(node_id)
        self.changed.emit()
        return on

    def set_skipped(self, node_id: str, skipped: bool) -> None:
        """Skip the node in the runs (it reports SKIPPED), or no longer."""
        if skipped:
            self._skipped.add(node_id)
            self._forced.pop(node_id, None)
        else:
            self._skipped.discard(node_id)
        if self._live is not None:
            self._live.skip(node_id, skipped)
        self.changed.emit()

    def set_forced(self, node_id: str, forced: Forced | None) -> None:
        """Give the node this result instead of running it (None: no longer): in the run
        going on, else in the next run; once.
        """
        self._forced.pop(node_id, None)
        if forced is not None:
            self._skipped.discard(node_id)
        if self._live is not None:
            self._live.skip(node_id, False)
            self._live.force(node_id, forced)
        elif forced is not None:
            self._forced[node_id] = forced
        self.changed.emit()

    def load(self, breakpoints: set[str]) -> None:
        """Start afresh with these breakpoints (another plan was opened)."""
        self._breakpoints = set(breakpoints)
        self._skipped.clear()
        self._forced.clear()
        self.changed.emit()

    def forget(self, known: set[str]) -> None:
        """Drop what is set on nodes that are no longer in the plan."""
        before = self.marked()
        self._breakpoints &= known
        self._skipped &= known
        self._forced = {k: v for k, v in self._forced.items() if k in known}
        if self.marked() != before:
            self.changed.emit()

    # ------------------------------------------------------------------ runs

    def debugger(self) -> Debugger:
        """The debugger of a run that starts now: the forced results go to it (and are
        forgotten here).
        """
        debugger = Debugger()
        for node_id in self._breakpoints:
            debugger.set_breakpoint(Breakpoint(node_id))
        for node_id in self._skipped:
            debugger.skip(node_id)
        for node_id, forced in self._forced.items():
            debugger.force(node_id, forced)
        self._live = debugger
        if self._forced:
            self._forced = {}
            self.changed.emit()
        return debugger

    def run_ended(self) -> None:
        self._live = None
