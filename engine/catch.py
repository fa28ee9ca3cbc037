"""Catch: a body and a handler, as Rethink Intera's Throw/Catch (DESIGN.md section 3).

The body is ticked; its SUCCESS is the Catch's. When it fails with one of the caught error
types, the caught error is written as ``"type: message"`` to the chosen parameter and the
handler runs; its result is the Catch's. A failure of a type not caught fails the Catch with
the same type and message, so an outer Catch can take it. A skipped body skips the Catch; a
skipped handler leaves the failure standing (the Catch fails as the body did).
"""

from __future__ import annotations

from collections.abc import Collection

from engine.blackboard import BlackboardError
from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.node import Node
from engine.status import FAILURE, SKIPPED, Status

__all__ = ["Catch"]


class Catch(Node):
    """Run the body; on a caught failure, run the handler instead of failing.

    Args:
        ctx: the tree's context.
        node_id: id of the spec node.
        name: label.
        errors: the error types the handler takes; None: every type.
        error_key: the blackboard name that receives the caught error ("": not kept).
    """

    kind = "catch"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str = "",
        errors: Collection[ErrorType] | None = None,
        error_key: str = "",
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.errors = None if errors is None else frozenset(errors)
        self.error_key = error_key
        self._handling = False

    def set_children(self, children: list[Node] | tuple[Node, ...]) -> None:
        if len(children) != 2:
            raise ValueError(
                f"catch {self.name!r} needs two children (body, handler), got {len(children)}"
            )
        super().set_children(children)

    def catches(self, error: ErrorType) -> bool:
        return self.errors is None or error in self.errors

    def update(self) -> Status:
        body, handler = self.children
        if not self._handling:
            status = body.tick()
            if status is not FAILURE:
                return status
            error = body.error or ErrorType.FAILED
            if not self.catches(error):
                return self.fail(body.message or f"{body.name} failed", error)
            self._handling = True
            caught = f"{error.value}: {body.message or body.name + ' failed'}"
            if self.error_key:
                try:
                    self.ctx.blackboard.set(self.error_key, caught, self.id)
                except BlackboardError as exc:  # a parameter declared of another type
                    return self.fail(str(exc), ErrorType.INVALID_INPUT)
            self.ctx.log(self.id, f"caught {caught}")
        status = handler.tick()
        if status is SKIPPED:
            why = body.message or f"{body.name} failed"
            return self.fail(f"{why} (its handler was skipped)", body.error or ErrorType.FAILED)
        if status is FAILURE:
            self.message = handler.message or f"{handler.name} failed"
        return status

    def on_reset(self) -> None:
        self._handling = False
