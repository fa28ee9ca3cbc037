"""A cell's stop as the executor sees it: held (PolyScope) or thrown into the plan (Intera).

A cell that can stop on its own gives the executor a hold check that answers a
:class:`Hold` (why in words, and the error type a Catch node matches) or None. When a stop
begins, the executor asks :func:`catchers`: if every running leaf the stop concerns
(:func:`stopped_leaves`: not those of the capabilities it spares, such as a camera's watch,
which goes on seeing while the arm stands, unless only they run) sits in the body of a Catch that takes the stop's
error type, the stop is *thrown*: those leaves fail with it (:func:`throw`) and each Catch's
handler runs, as Rethink Intera throws a collision during a move to the tree. Otherwise the
run is held until the cell is clear, as on a UR's pendant.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from engine.catch import Catch
from engine.error_types import ErrorType
from engine.node import Node

__all__ = ["Hold", "HoldCheck", "catchers", "stopped_leaves", "throw"]


@dataclass(frozen=True)
class Hold:
    """Why the cell cannot act now.

    Attributes:
        reason: in words ("protective stop").
        error: the error type a node fails with when the stop is thrown into the plan.
    """

    reason: str
    error: ErrorType = ErrorType.FAILED
    spares: frozenset[str] = frozenset()
    """Capabilities whose running operations the stop leaves running (they only look)."""


HoldCheck = Callable[[], Hold | None]


def stopped_leaves(leaves: list[Node], hold: Hold) -> list[Node]:
    """The running ``leaves`` the stop concerns: all but the operations of spared capabilities,
    unless nothing else runs. A robot stopped while the plan only watches was hit where it
    stood (a machine's arm came down on it): the watch is what the plan is doing then, so a
    Catch around it must hear of the stop, or the run stays held with the robot in the way.
    """
    if not hold.spares:
        return leaves
    concerned = [leaf for leaf in leaves if getattr(leaf, "capability", "") not in hold.spares]
    return concerned or leaves


def _catcher(leaf: Node, error: ErrorType) -> Catch | None:
    """The nearest Catch whose body holds ``leaf`` and that takes ``error``, or None."""
    child, parent = leaf, leaf.parent
    while parent is not None:
        if isinstance(parent, Catch) and parent.children[0] is child and parent.catches(error):
            return parent
        child, parent = parent, parent.parent
    return None


def catchers(leaves: list[Node], error: ErrorType) -> list[Catch] | None:
    """The Catch of each leaf when every one has a Catch that takes ``error``; else None."""
    found = [_catcher(leaf, error) for leaf in leaves]
    if not leaves or any(catch is None for catch in found):
        return None
    return [catch for catch in found if catch is not None]


def throw(leaves: list[Node], hold: Hold) -> None:
    """Fail each running leaf with the stop (its work halted); the next tick sees it."""
    for leaf in leaves:
        leaf.abort(hold.reason, hold.error)
