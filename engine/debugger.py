"""Breakpoints, stepping, skipped nodes and forced results for one run (no Qt, no robot).

A :class:`Debugger` decides *where* a run pauses; the executor that owns it does the pausing
(the engine thread waits inside the tick, the robot held as Pause holds it, the world of a
simulated cell running free) and says so with a :class:`~engine.events.RunPaused` event.

Only the nodes the debugger has something to do with are touched: each gets its own ``tick``
(an instance attribute over the class's method) that looks at the node before and after the
class's tick. A run with no breakpoint, skip or forced result ticks exactly as without a
debugger; stepping looks at status changes, which the executor already hears of.

- A breakpoint *before* a node pauses when the node is about to start (it is IDLE and its
  parent ticks it: once per start, not on every tick while it runs); *after* a node pauses
  once its tick turned it SUCCESS or FAILURE, before its parent sees the result. Either may
  have a condition, a script (:mod:`engine.script`) run in the node's scope: the breakpoint
  stops only when it is true (a script that fails stops too, naming the error).
- Stepping while paused: :attr:`Step.NEXT` pauses at the next status change of any node
  (a parent turns RUNNING after its first child did); :attr:`Step.OVER` runs the node
  paused at to its end (every other change passes) and pauses when it finishes, or at the
  next change outside it if it had finished already; a run to a node pauses before that
  node starts.
- A skipped node reports SKIPPED each time its parent would start it, for the whole run; a
  forced result (SUCCESS, or FAILURE with an error type that a Catch takes) is given once,
  the first time the node would start, instead of running it (one forced while the run is
  paused before the node is given when the run goes on).
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Callable
from dataclasses import dataclass

from engine.error_types import ErrorType
from engine.node import Node
from engine.script import Script, ScriptEnv, ScriptError, parse_script
from engine.status import FAILURE, IDLE, SKIPPED, SUCCESS, Status
from engine.tree import BehaviorTree

__all__ = ["Breakpoint", "Debugger", "Forced", "PauseAt", "Step", "BEFORE", "AFTER"]

BEFORE = "before"
AFTER = "after"

# Called on the engine thread where a run is to pause: (node, "before" / "after", why).
PauseAt = Callable[[Node, str, str], None]


class Step(str, enum.Enum):
    """How far a paused run goes before it pauses again."""

    NEXT = "next"  # the next status change of any node
    OVER = "over"  # the node paused at, to its end


@dataclass(frozen=True)
class Breakpoint:
    """Where a run pauses at one node.

    Attributes:
        node_id: the runtime id of the node.
        before: pause when the node is about to start.
        after: pause when its tick made it SUCCESS or FAILURE.
        condition: a script in the node's scope; empty: always (else only when true).
    """

    node_id: str
    before: bool = True
    after: bool = False
    condition: str = ""

    def __post_init__(self) -> None:
        if not (self.before or self.after):
            raise ValueError("a breakpoint is before a node, after it, or both")
        if self.condition.strip():
            parse_script(self.condition)  # ScriptSyntaxError names the line and column


@dataclass(frozen=True)
class Forced:
    """A result given to a node instead of running it.

    Attributes:
        status: SUCCESS or FAILURE.
        error: the FAILURE's type (a Catch that takes it runs its handler).
    """

    status: Status
    error: ErrorType | None = None

    def __post_init__(self) -> None:
        if self.status is not SUCCESS and self.status is not FAILURE:
            raise ValueError(f"a forced result is SUCCESS or FAILURE, not {self.status.value}")

    @property
    def message(self) -> str:
        if self.status is SUCCESS:
            return "forced to succeed by the operator"
        kind = (self.error or ErrorType.FAILED).value
        return f"forced to fail ({kind}) by the operator"


class Debugger:
    """Breakpoints, skips, forced results and stepping of the runs of one executor.

    Set them any time, from any thread (before the run or while it runs); the executor
    attaches the debugger to its tree and gives it where to pause.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._breakpoints: dict[str, Breakpoint] = {}
        self._scripts: dict[str, Script] = {}
        self._skipped: set[str] = set()
        self._forced: dict[str, Forced] = {}
        self._run_to = ""
        self._tree: BehaviorTree | None = None
        self._pause: PauseAt | None = None
        self.step: Step | None = None  # armed stepping: looked at on every status change
        self.current = ""  # the node the run paused at last ("" when none)

    # ------------------------------------------------------------------ what to do

    @property
    def breakpoints(self) -> dict[str, Breakpoint]:
        return dict(self._breakpoints)

    def set_breakpoint(self, breakpoint: Breakpoint) -> None:
        """Add or replace the breakpoint at ``breakpoint.node_id``."""
        with self._lock:
            self._breakpoints[breakpoint.node_id] = breakpoint
            if breakpoint.condition.strip():
                self._scripts[breakpoint.node_id] = parse_script(breakpoint.condition)
            else:
                self._scripts.pop(breakpoint.node_id, None)
            self._refresh(breakpoint.node_id)

    def clear_breakpoint(self, node_id: str) -> None:
        with self._lock:
            self._breakpoints.pop(node_id, None)
            self._scripts.pop(node_id, None)
            self._refresh(node_id)

    def skip(self, node_id: str, skipped: bool = True) -> None:
        """Skip the node for the run (or no longer)."""
        with self._lock:
            if skipped:
                self._skipped.add(node_id)
            else:
                self._skipped.discard(node_id)
            self._refresh(node_id)

    @property
    def skipped(self) -> frozenset[str]:
        return frozenset(self._skipped)

    def force(self, node_id: str, forced: Forced | None) -> None:
        """Give the node this result the next time it would start (None: no longer)."""
        with self._lock:
            if forced is None:
                self._forced.pop(node_id, None)
            else:
                self._forced[node_id] = forced
            self._refresh(node_id)

    @property
    def forced(self) -> dict[str, Forced]:
        return dict(self._forced)

    def arm(self, step: Step | None, run_to: str = "") -> None:
        """How far the run goes once resumed: a step, up to a node, or (both empty) on."""
        with self._lock:
            old, self._run_to = self._run_to, run_to
            self.step = step
            for node_id in {old, run_to} - {""}:
                self._refresh(node_id)

    # ------------------------------------------------------------------ the executor's side

    def attach(self, tree: BehaviorTree, pause: PauseAt) -> None:
        """Look at ``tree``'s nodes from now on; ``pause`` is called where the run pauses."""
        with self._lock:
            self._tree, self._pause = tree, pause
            for node_id in self._concerned():
                self._refresh(node_id)

    def on_status(self, node: Node, old: Status, new: Status) -> None:
        """A status change, while a step is armed (engine thread)."""
        step = self.step
        if step is None or new is IDLE:
            return
        tree = self._tree
        current = tree.nodes.get(self.current) if tree is not None else None
        if step is Step.OVER and current is not None:
            done = current.status.finished or current.status is SKIPPED
            if node is current:
                if not done:
                    return
            elif not done or self._inside(node, current):
                return
        self._stop(node, AFTER, f"step: {node.name} is {new.value}")

    # ------------------------------------------------------------------ inside

    def _concerned(self) -> set[str]:
        return {*self._breakpoints, *self._skipped, *self._forced, self._run_to} - {""}

    def _inside(self, node: Node, ancestor: Node) -> bool:
        parent = node.parent
        while parent is not None:
            if parent is ancestor:
                return True
            parent = parent.parent
        return False

    def _refresh(self, node_id: str) -> None:
        """Give the node its own tick while the debugger has something to do with it; take
        it away after (lock held).
        """
        tree = self._tree
        node = tree.nodes.get(node_id) if tree is not None else None
        if node is None:
            return
        wanted = node_id in self._concerned()
        has = "tick" in vars(node)
        if wanted and not has:
            node.tick = self._tick_of(node)  # type: ignore[method-assign]
        elif has and not wanted:
            del node.tick

    def _tick_of(self, node: Node) -> Callable[[], Status]:
        tick = type(node).tick.__get__(node)  # the class's tick, bound

        def debugged_tick() -> Status:
            status = node.status
            if status is IDLE:
                given = self._given(node)
                if given is not None:
                    return given
                if self._before(node):  # a result forced while paused there is given now
                    given = self._given(node)
                    if given is not None:
                        return given
            new = tick()
            if new is not status and (new is SUCCESS or new is FAILURE):
                self._after(node)
            return new

        return debugged_tick

    def _given(self, node: Node) -> Status | None:
        """A skip or a forced result instead of starting the node."""
        node_id = node.id
        if node_id in self._skipped:
            return node.give(SKIPPED, "skipped by the operator")
        with self._lock:
            forced = self._forced.pop(node_id, None)
            if forced is not None:
                self._refresh(node_id)
        if forced is None:
            return None
        return node.give(forced.status, forced.message, forced.error)

    def _before(self, node: Node) -> bool:
        """Pause before the node if it is to; True when the run paused."""
        if node.id == self._run_to:
            self.arm(None)
            self._stop(node, BEFORE, f"ran to {node.name}")
            return True
        breakpoint = self._breakpoints.get(node.id)
        if breakpoint is not None and breakpoint.before:
            why = self._hit(node)
            if why is not None:
                self._stop(node, BEFORE, f"breakpoint before {node.name}{why}")
                return True
        return False

    def _after(self, node: Node) -> None:
        breakpoint = self._breakpoints.get(node.id)
        if breakpoint is not None and breakpoint.after:
            why = self._hit(node)
            if why is not None:
                what = f"{node.name} is {node.status.value}"
                self._stop(node, AFTER, f"breakpoint after {node.name}: {what}{why}")

    def _hit(self, node: Node) -> str | None:
        """None when the node's breakpoint does not stop; else what to add to why it did."""
        script = self._scripts.get(node.id)
        if script is None:
            return ""
        tree = self._tree
        assert tree is not None
        env = ScriptEnv(tree.blackboard, key=tree.scopes.get(node.id), writer=node.id)
        try:
            if not script.check(env):
                return None
        except ScriptError as exc:
            return f" (its condition failed: {exc})"
        return f" ({script.text.strip()} is true)"

    def _stop(self, node: Node, where: str, why: str) -> None:
        self.step = None
        self.current = node.id
        pause = self._pause
        if pause is not None:
            pause(node, where, why)
