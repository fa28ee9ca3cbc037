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
        self._breakpoints: dict[str, Breakpoint] = {}
        self._skipped: set[str] = set()
        self._forced: dict[str, Forced] = {}
        self._live: Debugger | None = None  # the debugger of the run going on

    # ------------------------------------------------------------------ reading

    def has_breakpoint(self, node_id: str) -> bool:
        return node_id in self._breakpoints

    @property
    def breakpoints(self) -> frozenset[str]:
        return frozenset(self._breakpoints)

    def breakpoint(self, node_id: str) -> Breakpoint | None:
        """The breakpoint on ``node_id``: before or after it, with its condition."""
        return self._breakpoints.get(node_id)

    def all_breakpoints(self) -> list[Breakpoint]:
        return list(self._breakpoints.values())

    def is_skipped(self, node_id: str) -> bool:
        return node_id in self._skipped

    def forced(self, node_id: str) -> Forced | None:
        return self._forced.get(node_id)

    def note(self, node_id: str) -> str:
        """What the node shows of them besides a plain breakpoint's dot: "break after",
        "break if COUNT > 2", "skipped", "forced: succeed", "forced: grasp_failed".
        """
        breakpoint = self._breakpoints.get(node_id)
        parts = [_break_note(breakpoint)] if breakpoint is not None else []
        forced = self._forced.get(node_id)
        if node_id in self._skipped:
            parts.append("skipped")
        elif forced is not None and forced.status is SUCCESS:
            parts.append("forced: succeed")
        elif forced is not None:
            parts.append(f"forced: {forced.error.value if forced.error else 'fail'}")
        return "; ".join(p for p in parts if p)

    def marked(self) -> set[str]:
        """Every node with a breakpoint, a skip or a forced result."""
        return {*self._breakpoints, *self._skipped, *self._forced}

    # ------------------------------------------------------------------ changing

    def toggle_breakpoint(self, node_id: str) -> bool:
        """Set a breakpoint before ``node_id``, or clear the one it has; True when set now."""
        on = node_id not in self._breakpoints
        self.set_breakpoint(node_id, Breakpoint(node_id) if on else None)
        return on

    def set_breakpoint(self, node_id: str, breakpoint: Breakpoint | None) -> None:
        """Put ``breakpoint`` on ``node_id`` (None: clear it), in the run going on too."""
        if breakpoint is None:
            self._breakpoints.pop(node_id, None)
        else:
            self._breakpoints[node_id] = breakpoint
        if self._live is not None:
            self._live.clear_breakpoint(node_id)
            if breakpoint is not None:
                self._live.set_breakpoint(breakpoint)
        self.changed.emit()

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

    def load(self, breakpoints: list[Breakpoint]) -> None:
        """Start afresh with these breakpoints (another plan was opened)."""
        self._breakpoints = {b.node_id: b for b in breakpoints}
        self._skipped.clear()
        self._forced.clear()
        self.changed.emit()

    def forget(self, known: set[str]) -> None:
        """Drop what is set on nodes that are no longer in the plan."""
        before = self.marked()
        self._breakpoints = {k: v for k, v in self._breakpoints.items() if k in known}
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
        for breakpoint in self._breakpoints.values():
            debugger.set_breakpoint(breakpoint)
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


def _break_note(breakpoint: Breakpoint) -> str:
    """What the node shows of its breakpoint: nothing for a plain one before it (the dot says
    it), else "break after", "break if COUNT > 2"...
    """
    where = "" if breakpoint.before and not breakpoint.after else "break "
    where += "after" if breakpoint.after and not breakpoint.before else ""
    where += "before and after" if breakpoint.before and breakpoint.after else ""
    if breakpoint.condition:
        where = f"{where or 'break'} if {breakpoint.condition}"
    return where.strip()
