"""Logic nodes with several children: Sequence, Selector, Parallel and reactive variants.

Sequence and Selector keep their place (memory semantics, as BehaviorTree.CPP's Sequence and
py_trees' ``memory=True``): a RUNNING child is resumed, finished children are not ticked
again until the node is reset. The reactive variants re-check their condition children every
tick and halt a running sibling when the answer changes.

A SKIPPED child is passed over as BehaviorTree.CPP's composites do: a Sequence or a Selector
goes on to the next child, and is SKIPPED itself when every child was skipped. The reactive
variants and a Parallel check a skipped child afresh on each tick.
"""

from __future__ import annotations

from engine.context import TreeContext
from engine.node import Node
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = [
    "Sequence",
    "SequenceWithMemory",
    "AsyncSequence",
    "AsyncFallback",
    "Selector",
    "Parallel",
    "ParallelPolicy",
    "ReactiveSequence",
    "ReactiveSelector",
]


class _InOrder(Node):
    """The walk of a Sequence or a Selector: children in order, the next after ``next_on``.

    It ends with the first child's result that is not ``next_on`` or SKIPPED (halting
    nothing), or with ``next_on`` when every child gave it or was skipped (SKIPPED when every
    child was skipped).
    """

    next_on: Status = SUCCESS
    # The message when every child gave ``next_on`` ("" leaves the message alone).
    exhausted_message = ""

    def _stopped(self, child: Node, status: Status) -> Status:
        if status is FAILURE:
            self.message = f"{child.name} failed"
        return status

    def _exhausted(self) -> Status:
        children = self.children
        if children and all(child.status is SKIPPED for child in children):
            self.message = "every child was skipped"
            return SKIPPED
        if self.exhausted_message:
            self.message = self.exhausted_message
        return self.next_on


class _Resuming(_InOrder):
    """An in-order walk that keeps its place: a RUNNING child is resumed next tick.

    With ``yields`` (BehaviorTree.CPP's AsyncSequence and AsyncFallback), a child that gave
    ``next_on`` on its first tick hands the tick back: the node is RUNNING and the next child
    starts on the next tick.
    """

    yields = False

    def __init__(self, ctx: TreeContext, node_id: str, name: str = "") -> None:
        super().__init__(ctx, node_id, name)
        self._index = 0

    def update(self) -> Status:
        children = self.children
        next_on = self.next_on
        index = self._index
        count = len(children)
        while index < count:
            child = children[index]
            before = child.status
            status = child.tick()
            if status is next_on or status is SKIPPED:
                index += 1
                if self.yields and status is next_on and before is IDLE and index < count:
                    self._index = index
                    self.ctx.wake()  # BehaviorTree.CPP's emitWakeUpSignal: tick again soon
                    return RUNNING
                continue
            self._index = index
            return self._stopped(child, status)
        self._index = index
        return self._exhausted()

    def on_reset(self) -> None:
        self._index = 0


class Sequence(_Resuming):
    """Children in order, the next only after SUCCESS; FAILURE at the first failure."""

    kind = "sequence"


class SequenceWithMemory(Sequence):
    """BehaviorTree.CPP's SequenceWithMemory: a Sequence that keeps its place through a
    failure and a halt, so that, ticked again, it resumes at the child that failed or was
    running; it starts from the first child only after it has succeeded. Like an
    AsyncSequence (and as its source does), it gives the tick back after each child that
    succeeded at once.
    """

    kind = "sequence_with_memory"
    yields = True

    def update(self) -> Status:
        status = super().update()
        if self._index >= len(self.children):
            self._index = 0
        return status

    def on_reset(self) -> None:
        """Keeps its place: a reset is BehaviorTree.CPP's halt, which keeps it too."""


class AsyncSequence(Sequence):
    """BehaviorTree.CPP's AsyncSequence: a Sequence that gives the tick back after each child
    that succeeded at once.
    """

    kind = "async_sequence"
    yields = True


class Selector(_Resuming):
    """Children in order until one succeeds; FAILURE when all failed (a fallback)."""

    kind = "selector"
    next_on = FAILURE
    exhausted_message = "every option failed"


class AsyncFallback(Selector):
    """BehaviorTree.CPP's AsyncFallback: a Selector that gives the tick back after each child
    that failed at once.
    """

    kind = "async_fallback"
    yields = True


class ParallelPolicy:
    """When a Parallel finishes: ``success`` is "all", "any" or a count M; ``failure`` is
    "any" (= 1) or a count N. A negative count is BehaviorTree.CPP's: -1 is every child,
    -2 all but one, and so on (never below 0). A count of 0, which BehaviorTree.CPP takes,
    is refused.
    """

    __slots__ = ("failure", "success")

    def __init__(self, success: str | int = "all", failure: str | int = "any") -> None:
        if not (success in ("all", "any") or _is_count(success)):
            raise ValueError(f"success policy must be 'all', 'any' or a count, not {success!r}")
        if not (failure == "any" or _is_count(failure)):
            raise ValueError(f"failure policy must be 'any' or a count, not {failure!r}")
        self.success = success
        self.failure = failure

    @property
    def counts_skipped(self) -> bool:
        """A skipped child counts as a success (BehaviorTree.CPP: a negative success count)."""
        return self.success == "all" or (isinstance(self.success, int) and self.success < 0)

    def thresholds(self, n_children: int) -> tuple[int, int]:
        """(successes needed, failures that end it) for ``n_children`` children."""
        if self.success == "all":
            need = n_children
        elif self.success == "any":
            need = 1
        else:
            need = _threshold(int(self.success), n_children)
        fail = 1 if self.failure == "any" else _threshold(int(self.failure), n_children)
        return need, fail


def _is_count(value: object) -> bool:
    """A whole number other than 0 (a count of 0 would end the Parallel before it starts)."""
    return isinstance(value, int) and not isinstance(value, bool) and value != 0


def _threshold(count: int, n_children: int) -> int:
    """A count of children; a negative one counts back from all of them."""
    return max(n_children + count + 1, 0) if count < 0 else count


class Parallel(Node):
    """Ticks every unfinished child each tick, in order, and finishes as soon as its policy
    is met (the children after that one are not ticked); then halts the children still
    running.

    A skipped child is checked afresh each tick. As in BehaviorTree.CPP (a success count of
    -1), a skipped child counts as a success for the policy "all"; when every child is
    skipped under another policy, the Parallel is SKIPPED.
    """

    kind = "parallel"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str = "",
        policy: ParallelPolicy | None = None,
    ) -> None:
        super().__init__(ctx, node_id, name)
        self.policy = policy or ParallelPolicy()
        self._need = 0
        self._fail = 1

    def set_children(self, children: list[Node] | tuple[Node, ...]) -> None:
        super().set_children(children)
        self._need, self._fail = self.policy.thresholds(len(self.children))

    def update(self) -> Status:
        children = self.children
        succeeded = sum(child.status is SUCCESS for child in children)
        failed = sum(child.status is FAILURE for child in children)
        skipped = 0
        finished = self._finished(succeeded, failed, skipped)  # no children, or too few
        if finished is not None:
            return finished
        for child in children:
            status = child.status
            if status is not SUCCESS and status is not FAILURE:
                status = child.recheck() if status is SKIPPED else child.tick()
                if status is SUCCESS:
                    succeeded += 1
                elif status is FAILURE:
                    failed += 1
                elif status is SKIPPED:
                    skipped += 1
            # As BehaviorTree.CPP's: the policy is checked after each child, so a Parallel
            # that has its answer does not start the children after it.
            finished = self._finished(succeeded, failed, skipped)
            if finished is not None:
                self._halt_running()
                return finished
        return SKIPPED if skipped and skipped == len(children) else RUNNING

    def _finished(self, succeeded: int, failed: int, skipped: int) -> Status | None:
        """SUCCESS or FAILURE when the policy is met by these counts, else None."""
        if succeeded >= self._need or (
            self.policy.counts_skipped and succeeded + skipped >= self._need
        ):
            return SUCCESS
        if failed >= self._fail:
            self.message = f"{failed} of {len(self.children)} failed"
            return FAILURE
        if len(self.children) - failed < self._need:
            self.message = "too many children failed to reach the success policy"
            return FAILURE
        return None

    def _halt_running(self) -> None:
        for child in self.children:
            if child.status is RUNNING:
                child.reset()


def _halt_after(children: tuple[Node, ...], index: int) -> None:
    for child in children[index + 1 :]:
        if child.status is RUNNING:
            child.reset()


class _Rechecking(_InOrder):
    """An in-order walk from the first child every tick, conditions re-checked.

    The child it stops at halts its running later siblings.
    """

    def update(self) -> Status:
        children = self.children
        next_on = self.next_on
        for index, child in enumerate(children):
            if child.is_condition or child.status is SKIPPED:
                status = child.recheck()
            else:
                status = child.tick()
            if status is next_on or status is SKIPPED:
                continue
            _halt_after(children, index)
            return self._stopped(child, status)
        return self._exhausted()


class ReactiveSequence(_Rechecking):
    """A Sequence whose condition children are re-checked every tick.

    When a condition that held turns false, the running sibling is halted and the node
    fails: the way a plan stops when a person enters a region. Finished actions are not
    started again (they stay latched until the node is reset).
    """

    kind = "reactive_sequence"


class ReactiveSelector(_Rechecking):
    """A Selector whose condition children are re-checked every tick; when a higher
    priority condition succeeds, the running lower-priority sibling is halted.
    """

    kind = "reactive_selector"
    next_on = FAILURE
    exhausted_message = "every option failed"
