"""BehaviorTree.CPP 4.10's other control nodes: IfThenElse, WhileDoElse, Switch2..6,
ParallelAll and TryCatch, with its semantics (src/controls/*.cpp).

Where BehaviorTree.CPP resets its children as it finishes, these nodes latch their result
as every node of this engine does, and the reset that follows (from a parent, or a new run)
clears the children. A case BehaviorTree.CPP meets with an exception (a condition child that
was skipped) fails the node with ``invalid_input`` instead.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from engine.context import TreeContext
from engine.error_types import ErrorType
from engine.node import Node
from engine.port_text import port_text, same_text
from engine.script.values import ScriptEnv
from engine.status import FAILURE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = ["IfThenElse", "WhileDoElse", "Switch", "ParallelAll", "TryCatch"]


def _halt(children: tuple[Node, ...]) -> None:
    for child in children:
        if child.status is RUNNING:
            child.reset()


def _skipped_condition(node: Node) -> Status:
    return node.fail(
        f"its condition {node.children[0].name} was skipped (BehaviorTree.CPP stops with an "
        "error there)",
        ErrorType.INVALID_INPUT,
    )


class IfThenElse(Node):
    """Ticks the condition (first child) until it finishes, then the second child on SUCCESS
    or the third on FAILURE (without a third: FAILURE); the branch's result is its result.
    """

    kind = "if_then_else"

    def __init__(self, ctx: TreeContext, node_id: str, name: str = "") -> None:
        super().__init__(ctx, node_id, name)
        self._branch = 0

    def update(self) -> Status:
        children = self.children
        if self._branch == 0:
            status = children[0].tick()
            if status is RUNNING:
                return RUNNING
            if status is SKIPPED:
                return _skipped_condition(self)
            if status is FAILURE and len(children) < 3:
                return self.fail(f"{children[0].name} failed")
            self._branch = 1 if status is SUCCESS else 2
        return children[self._branch].tick()

    def on_reset(self) -> None:
        self._branch = 0


class WhileDoElse(Node):
    """Ticks the condition (first child) afresh on every tick: while it succeeds, the second
    child runs (a running third is halted); when it fails, the third runs (a running second
    is halted), or without a third the node fails.
    """

    kind = "while_do_else"

    def update(self) -> Status:
        children = self.children
        condition = children[0].recheck()
        if condition is RUNNING:
            return RUNNING
        if condition is SKIPPED:
            _halt(children)
            return _skipped_condition(self)
        if condition is SUCCESS:
            if len(children) == 3:
                _halt(children[2:])
            return children[1].tick()
        _halt(children[1:2])
        if len(children) < 3:
            return self.fail(f"{children[0].name} failed")
        return children[2].tick()


class Switch(Node):
    """BehaviorTree.CPP's Switch2 .. Switch6: ticks the child of the first case whose text
    equals the variable's (as text, as an integer or as a real), else the last child (the
    default). When the match changes while a child runs, that child is halted.

    The number of cases is the number of children less one. A case left empty is not
    compared (BehaviorTree.CPP: a case port not given).

    Args:
        variable: the variable's text, usually ``{key}`` (an entry read on every tick).
        cases: the cases' texts, ``case_1`` first (``{key}`` reads an entry).
        key: a name -> its blackboard key (the node's scope).
        enums: names that read as integers.
    """

    kind = "switch"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        variable: str,
        cases: tuple[str, ...],
        *,
        key: Callable[[str], str] | None = None,
        enums: Mapping[str, int] | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.variable = variable
        self.cases = cases
        self._env = ScriptEnv(ctx.blackboard, enums, key=key, writer=node_id)
        self._running: int | None = None

    def match(self) -> int:
        """The index of the child the variable selects now."""
        default = len(self.children) - 1
        value = port_text(self.variable, self._env)
        if value is None:
            return default
        for index, case in enumerate(self.cases[:default]):
            text = port_text(case, self._env) if case else None
            if text is not None and same_text(value, text, self._env.enums):
                return index
        return default

    def update(self) -> Status:
        index = self.match()
        running = self._running
        if running is not None and running != index:
            self.children[running].reset()
        status = self.children[index].tick()
        self._running = index if status is RUNNING else None
        return status

    def on_reset(self) -> None:
        self._running = None


class ParallelAll(Node):
    """BehaviorTree.CPP's ParallelAll: ticks every child until all have finished (a skipped
    one is checked afresh each tick), then fails when at least ``max_failures`` of them
    failed, else succeeds. A negative ``max_failures`` counts back from all children
    (-1: all of them). SKIPPED when every child was skipped.
    """

    kind = "parallel_all"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", max_failures: int = 1
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.max_failures = max_failures

    def threshold(self) -> int:
        """How many failures fail it, for its number of children."""
        count = self.max_failures
        return max(len(self.children) + count + 1, 0) if count < 0 else count

    def update(self) -> Status:
        children = self.children
        skipped = done = failed = 0
        for child in children:
            status = child.status
            if status is SKIPPED:
                status = child.recheck()
            elif status is not SUCCESS and status is not FAILURE:
                status = child.tick()
            if status is SKIPPED:
                skipped += 1
            elif status is SUCCESS or status is FAILURE:
                done += 1
                failed += status is FAILURE
        if skipped == len(children):
            self.message = "every child was skipped"
            return SKIPPED
        if skipped + done < len(children):
            return RUNNING
        if failed >= self.threshold():
            return self.fail(f"{failed} of {len(children)} failed")
        return SUCCESS


class TryCatch(Node):
    """BehaviorTree.CPP's TryCatch: the children but the last run as a Sequence (the try
    block); when one fails, the last child (the catch) runs, and when it finishes the node
    fails whatever the catch gave. SUCCESS when the try block succeeded, SKIPPED when all its
    children were skipped.

    With ``catch_on_halt``, a halt during the try block runs the catch child for one tick
    (halting it if it is still running), as a cleanup.
    """

    kind = "try_catch"

    def __init__(
        self, ctx: TreeContext, node_id: str, name: str = "", catch_on_halt: bool = False
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.catch_on_halt = catch_on_halt
        self._index = 0
        self._caught = ""

    def update(self) -> Status:
        children = self.children
        tries = len(children) - 1
        while not self._caught and self._index < tries:
            child = children[self._index]
            status = child.tick()
            if status is RUNNING:
                return RUNNING
            if status is FAILURE:
                self._caught = child.name
            else:
                self._index += 1
        if not self._caught:
            if all(child.status is SKIPPED for child in children[:tries]):
                self.message = "every child of its try block was skipped"
                return SKIPPED
            return SUCCESS
        if children[-1].tick() is RUNNING:
            return RUNNING
        return self.fail(f"{self._caught} failed; the catch ran")

    def on_halt(self) -> None:
        if not self.catch_on_halt or self._caught:
            return
        catch = self.children[-1]
        catch.tick()
        catch.reset()  # halts it if it still runs; BehaviorTree.CPP's halt leaves it idle

    def on_reset(self) -> None:
        self._index = 0
        self._caught = ""
