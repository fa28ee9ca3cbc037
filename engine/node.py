"""The runtime node: tick, latching and reset (paper section III-B).

A node that returned SUCCESS or FAILURE is latched: ticking it again returns that status
without evaluating anything, until it is reset. Reset clears the whole subtree and halts the
leaves that are running; halting happens exactly once per run of a leaf, because a reset
node is IDLE and resetting an IDLE node does nothing.

A node may carry pre- and post-conditions (:mod:`engine.conditions`, BehaviorTree.CPP's
``_skipIf`` ...): :meth:`tick` checks them around :meth:`update`. SKIPPED latches like a
result.

Subclasses implement :meth:`update` (one evaluation; must not block), and may implement
:meth:`on_halt` (the node was RUNNING and is being reset) and :meth:`on_reset`
(clear private state).
"""

from __future__ import annotations

from collections.abc import Iterator

from engine.conditions import Condition, ConditionFailed, NodeConditions
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = ["Node"]


class Node:
    """Base of all runtime nodes.

    Attributes:
        id: the stable id of the spec node this was built from.
        name: the label shown to users.
        status: the last status returned (IDLE after a reset).
        message: why the node failed, or what it is doing; may be empty.
        error: the type of the node's FAILURE (None while it has not failed).
        children: child nodes in tick order (empty for leaves).
        is_condition: True for predicates (and decorators of them) that reactive
            composites re-check every tick.
        conditions: its pre- and post-conditions (None: it has none).
    """

    kind = "node"
    is_condition = False
    conditions: NodeConditions | None = None

    def __init__(self, ctx: TreeContext, node_id: str, name: str = "") -> None:
        self.ctx = ctx
        self.id = node_id
        self.name = name or self.kind
        self.status: Status = IDLE
        self.message = ""
        self.error: ErrorType | None = None
        self.children: tuple[Node, ...] = ()
        self.parent: Node | None = None

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} {self.status.value}>"

    # ------------------------------------------------------------------ ticking

    def tick(self) -> Status:
        """Evaluate once, unless latched; returns the status."""
        status = self.status
        if status is SUCCESS or status is FAILURE or status is SKIPPED:
            return status
        if self.conditions is not None:
            return self._tick_with_conditions(status)
        return self._settle(status, self.update())

    def _settle(self, status: Status, new: Status) -> Status:
        """Take the tick's result ``new`` (was ``status``) and tell the sink of a change."""
        if new is not status:
            if new is FAILURE and self.error is None:
                self.error = self._child_error()
            self.status = new
            sink = self.ctx.status_sink
            if sink is not None:
                sink(self, status, new)
        return new

    def _tick_with_conditions(self, status: Status) -> Status:
        """:meth:`tick` as BehaviorTree.CPP's executeTick runs a node's conditions."""
        conditions = self.conditions
        assert conditions is not None
        try:
            given = conditions.before(running=status is RUNNING)
        except ConditionFailed as exc:
            if status is RUNNING:  # a `while` that cannot be checked stops the node
                self.reset()
                status = IDLE
            new = self.fail(str(exc), ErrorType.INVALID_INPUT)
        else:
            if given is None:
                new = self.update()
            else:
                new, condition = given
                if new is SKIPPED and status is RUNNING:  # `while` turned false: halt it
                    self.reset()
                    status = IDLE
                self._given(new, condition)
            if new is SUCCESS or new is FAILURE:
                try:
                    conditions.after(new)
                except ConditionFailed as exc:
                    new = self.fail(str(exc), ErrorType.INVALID_INPUT)
        return self._settle(status, new)

    def give(self, status: Status, message: str, error: ErrorType | None = None) -> Status:
        """Take a result from outside instead of ticking (the operator skipped the node or
        forced its result): the node is not evaluated, its listeners hear of the change.
        """
        self.message = message
        self.error = error if status is FAILURE else None
        return self._settle(self.status, status)

    def _given(self, status: Status, condition: Condition) -> None:
        """The message of a result a pre-condition gave."""
        script = self.conditions.scripts[condition] if self.conditions is not None else None
        text = script.text.strip() if script is not None else ""
        if condition is Condition.WHILE:
            self.message = f"skipped: its while condition ({text}) is false"
        elif status is SKIPPED:
            self.message = f"skipped: its skip condition ({text}) is true"
        elif status is FAILURE:
            self.message = f"its failure condition ({text}) is true"
            self.error = ErrorType.FAILED
        else:
            self.message = f"its success condition ({text}) is true"

    def update(self) -> Status:
        """One evaluation. Must return quickly; long work returns RUNNING."""
        raise NotImplementedError(f"{type(self).__name__} must implement update()")

    # ------------------------------------------------------------------ reset / halt

    def reset(self) -> None:
        """Back to IDLE with the whole subtree; running leaves are halted first.

        Never raises: halting errors become log lines.
        """
        status = self.status
        if status is IDLE:
            return
        for child in self.children:
            child.reset()
        if status is RUNNING:
            try:
                self.on_halt()
            except Exception as exc:  # a capability's cancel must not break the reset
                self.ctx.log(self.id, f"error while halting: {type(exc).__name__}: {exc}")
            self._run_on_halted()
        self.on_reset()
        self.message = ""
        self.error = None
        self.status = IDLE
        sink = self.ctx.status_sink
        if sink is not None:
            sink(self, status, IDLE)

    halt = reset

    def abort(self, message: str, error: ErrorType) -> None:
        """Fail a RUNNING node from outside a tick (the executor throws a cell's stop into
        it): its work is halted and it latches FAILURE, which its parents see on the next
        tick. Nothing happens to a node that is not running. Never raises.
        """
        status = self.status
        if status is not RUNNING:
            return
        try:
            self.on_halt()
        except Exception as exc:  # a capability's cancel must not break the throw
            self.ctx.log(self.id, f"error while halting: {type(exc).__name__}: {exc}")
        self._run_on_halted()
        self.message = message
        self.error = error
        self.status = FAILURE
        sink = self.ctx.status_sink
        if sink is not None:
            sink(self, status, FAILURE)

    def recheck(self) -> Status:
        """Evaluate a finished condition afresh (reset + tick) for reactive composites.

        Listeners hear only of real changes: a condition that held and still holds makes no
        SUCCESS -> IDLE -> SUCCESS noise every tick.
        """
        if self.status is RUNNING:
            return self.tick()
        nodes = list(self.iterate())
        before = [node.status for node in nodes]
        ctx = self.ctx
        sink = ctx.status_sink
        ctx.status_sink = None
        try:
            self.reset()
            status = self.tick()
        finally:
            ctx.status_sink = sink
        if sink is not None:
            for node, old in zip(nodes, before, strict=True):
                if node.status is not old:
                    sink(node, old, node.status)
        return status

    def _run_on_halted(self) -> None:
        """The ``on_halted`` condition of a node halted while RUNNING (never raises)."""
        if self.conditions is None:
            return
        try:
            self.conditions.halted()
        except ConditionFailed as exc:
            self.ctx.log(self.id, str(exc))

    def on_halt(self) -> None:
        """The node was RUNNING and is being reset: stop the work it started."""

    def on_reset(self) -> None:
        """Clear private state kept between ticks."""

    # ------------------------------------------------------------------ structure

    def set_children(self, children: list[Node] | tuple[Node, ...]) -> None:
        self.children = tuple(children)
        for child in self.children:
            child.parent = self

    def iterate(self) -> Iterator[Node]:
        """This node and all below it, depth first, in tick order."""
        yield self
        for child in self.children:
            yield from child.iterate()

    def fail(self, message: str, error: ErrorType | None = None) -> Status:
        """Set the message and error type and return FAILURE (``return self.fail(...)``).

        ``error`` None: the type of the failed child, else ``failed`` (see :meth:`tick`).
        """
        self.message = message
        self.error = error
        return FAILURE

    def _child_error(self) -> ErrorType:
        """The type a failure that named none carries: its last failed child's, else failed.

        So a Sequence, a Selector or a pass-through decorator passes its child's type up to
        a Catch without each one saying so.
        """
        for child in reversed(self.children):
            if child.status is FAILURE and child.error is not None:
                return child.error
        return ErrorType.FAILED
