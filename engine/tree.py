"""The root of a tree and the tree as a whole.

The root holds the run policy: ``once`` returns its child's result; ``until_success``
resets the child after a FAILURE and runs it again (the paper's "evaluated until it returns
SUCCESS"), but gives up after ``give_up_after`` identical failures in a row (the same first
failing node with the same error type and message: trying again changes nothing); ``forever``
resets the child after every result (a plan meant to run until stopped, with no limit). A
child that is SKIPPED (its pre-conditions, or all its children, skipped it) ends a ``once``
or ``until_success`` run with SKIPPED, as BehaviorTree.CPP's tree returns it; ``forever``
starts it again.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Iterator

from engine.blackboard import Blackboard
from engine.context import TreeContext
from engine.failure_words import failed_words, node_title, stopped_words
from engine.node import Node
from engine.status import FAILURE, IDLE, RUNNING, SKIPPED, SUCCESS, Status

__all__ = ["RunPolicy", "Root", "BehaviorTree", "DEFAULT_GIVE_UP_AFTER", "first_failed"]

# How many identical failures in a row a root that runs until success takes before it gives
# up, unless the plan says otherwise (0: no limit).
DEFAULT_GIVE_UP_AFTER = 5


class RunPolicy(str, enum.Enum):
    """How often the root runs its child."""

    ONCE = "once"
    UNTIL_SUCCESS = "until_success"
    FOREVER = "forever"


def first_failed(node: Node) -> Node:
    """The node a FAILURE started at: down through the first failed child in tick order
    (the first option a Selector tried, the body of a Catch whose handler failed too, a
    Retry's last attempt) to a node none of whose children failed (a leaf, a Timeout that
    ran out, a Force failure).
    """
    while True:
        failed = next((child for child in node.children if child.status is FAILURE), None)
        if failed is None:
            return node
        node = failed


def _failure_key(node: Node) -> tuple[str, str, str]:
    return node.id, node.error.value if node.error is not None else "", node.message


class Root(Node):
    """The tree's root: ticks its one child and applies the run policy.

    Args:
        give_up_after: with ``until_success``, fail after this many identical failures of
            the child in a row (0: never give up).
    """

    kind = "root"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str = "",
        policy: RunPolicy = RunPolicy.ONCE,
        give_up_after: int = DEFAULT_GIVE_UP_AFTER,
    ) -> None:
        super().__init__(ctx, node_id, name or "root")
        if give_up_after < 0:
            raise ValueError(f"give up after must be 0 (no limit) or more, not {give_up_after}")
        self.policy = RunPolicy(policy)
        self.give_up_after = give_up_after
        self.runs = 0  # finished runs of the child
        self._last_failure: tuple[str, str, str] | None = None
        self.in_a_row = 0  # identical failures of the child in a row

    def update(self) -> Status:
        child = self.children[0]
        status = child.tick()
        if status is RUNNING:
            return RUNNING
        self.runs += 1
        if self.policy is RunPolicy.ONCE or (
            self.policy is RunPolicy.UNTIL_SUCCESS and (status is SUCCESS or status is SKIPPED)
        ):
            if status is FAILURE:
                self.message = child.message or f"{child.name} failed"
            elif status is SKIPPED:
                self.message = child.message or f"{child.name} was skipped"
            return status
        if self.policy is RunPolicy.UNTIL_SUCCESS and self._gives_up(first_failed(child)):
            return FAILURE
        # Run again from a clean subtree on the next tick.
        self.ctx.log(self.id, f"run {self.runs} ended with {status.value}; starting again")
        child.reset()
        return RUNNING

    def _gives_up(self, origin: Node) -> bool:
        """Count the failure that started at ``origin``; True (with the root's message and
        error type set) when it is the ``give_up_after``-th identical one in a row.
        """
        key = _failure_key(origin)
        self.in_a_row = self.in_a_row + 1 if key == self._last_failure else 1
        self._last_failure = key
        if not self.give_up_after or self.in_a_row < self.give_up_after:
            return False
        title = node_title(origin.kind, origin.name, leaf=not origin.children)
        why = failed_words(title, key[1], origin.message)
        self.fail(f"{stopped_words(self.in_a_row)}: {why}", origin.error)
        return True

    def on_reset(self) -> None:
        self.runs = 0
        self._last_failure = None
        self.in_a_row = 0


# How the earlier children of a parent count when a run starts at a later one.
_SKIPPED_AS: dict[str, Status] = {
    "sequence": SUCCESS,
    "reactive_sequence": SUCCESS,
    "selector": FAILURE,
    "reactive_selector": FAILURE,
    "sequence_with_memory": SUCCESS,
    "async_sequence": SUCCESS,
    "async_fallback": FAILURE,
}


class BehaviorTree:
    """A runnable tree: the root, its context, and its nodes by id.

    Attributes:
        scopes: node id -> how a name in that node's scope becomes a blackboard key (the
            builder fills it for the nodes inside subtree instances; a node not in it is at
            the top, where a name is its key).
    """

    def __init__(self, root: Root, ctx: TreeContext) -> None:
        self.root = root
        self.ctx = ctx
        self.nodes: dict[str, Node] = {node.id: node for node in root.iterate()}
        self.scopes: dict[str, Callable[[str], str]] = {}

    @property
    def status(self) -> Status:
        return self.root.status

    @property
    def blackboard(self) -> Blackboard:
        return self.ctx.blackboard

    def tick(self) -> Status:
        """One tick from the root."""
        self.ctx.tick_count += 1
        return self.root.tick()

    def reset(self) -> None:
        """Halt what runs and put every node back to IDLE."""
        self.root.reset()
        # A tick cut short by an exception can leave a RUNNING node under a parent that is
        # still IDLE (its update never returned), and resetting an IDLE node does nothing:
        # sweep for such nodes so that their work is halted too.
        for node in self.root.iterate():
            if node.status is not IDLE:
                node.reset()

    def start_at(self, node_id: str) -> dict[str, Status]:
        """Prepare a fresh tree to run from ``node_id`` on ("resume from this node").

        Along the path from the root to the node, the children of a sequence before the path
        are marked SUCCESS (done) and the options of a selector before it FAILURE (tried):
        finished nodes are latched, so the first tick goes down to ``node_id`` without
        evaluating them. Other parents (a Parallel, a decorator) tick as usual.

        Returns:
            The ids marked, with their status.

        Raises:
            KeyError: no node of that id in this tree.
            ValueError: the tree has been ticked already.
        """
        if self.root.status is not IDLE:
            raise ValueError("a tree starts at a node only before its first tick")
        child = self.nodes[node_id]
        marked: dict[str, Status] = {}
        while child.parent is not None:
            parent = child.parent
            done = _SKIPPED_AS.get(parent.kind)
            if done is not None:
                for sibling in parent.children[: parent.children.index(child)]:
                    sibling.status = done
                    marked[sibling.id] = done
            child = parent
        return marked

    def iterate(self) -> Iterator[Node]:
        return self.root.iterate()

    def running_leaves(self) -> list[Node]:
        return [n for n in self.root.iterate() if not n.children and n.status is RUNNING]

    def tick_until_done(self, max_ticks: int = 1_000_000) -> Status:
        """Tick until the root finishes (tests and benchmarks; no waiting between ticks)."""
        for _ in range(max_ticks):
            status = self.tick()
            if status is not RUNNING:
                return status
        return RUNNING
