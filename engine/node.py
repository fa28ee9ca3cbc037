"""The runtime node: tick, latching and reset (paper section III-B).

A node that returned SUCCESS or FAILURE is latched: ticking it again returns that status
without evaluating anything, until it is reset. Reset clears the whole subtree and halts the
leaves that are running; halting happens exactly once per run of a leaf, because a reset
node is IDLE and resetting an IDLE node does nothing.

Subclasses implement :meth:`update` (one evaluation; must not block), and may implement
:meth:`on_halt` (the node was RUNNING and is being reset) and :meth:`on_reset`
(clear private state).
"""

from __future__ import annotations

from collections.abc import Iterator

from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status

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
    """

    kind = "node"
    is_condition = False

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
        if status is SUCCESS or status is FAILURE:
            return status
        new = self.update()
        if new is not status:
            if new is FAILURE and self.error is None:
                self.error = self._child_error()
            self.status = new
            sink = self.ctx.status_sink
            if sink is not None:
                sink(self, status, new)
        return new

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
