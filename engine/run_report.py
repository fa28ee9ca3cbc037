"""Which nodes failed on the way to a result, and which node carried on past each failure.

A plan that succeeds through a fallback (a Selector trying its next child, a Retry, a root
that runs until success) hides the failures it recovered from; :class:`FailureLog`, a run
listener, keeps them so a report can say "move to CUP_POSE failed (...), caught by Selector
'transfer or wait'". The catcher of a failure is the nearest ancestor whose next result after
it was not a failure: the failure stopped there.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

from engine.build import ROOT_ID
from engine.events import Event, StatusChanged
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status

__all__ = ["CaughtFailure", "FailureLog"]

_RESULTS = (Status.SUCCESS, Status.FAILURE)


@dataclass(frozen=True)
class CaughtFailure:
    """A node that failed (``times`` times, the last with ``message``) and what caught it."""

    node: str
    message: str
    caught_by: str
    times: int

    def describe(self) -> str:
        """One line: ``move to CUP_POSE failed 2 times (why), caught by Selector 'x'``."""
        times = "" if self.times == 1 else f" {self.times} times"
        why = f" ({self.message})" if self.message else ""
        return f"{self.node} failed{times}{why}, caught by {self.caught_by}"


class FailureLog:
    """A run listener that keeps each node's results, then names the failures caught on the way.

    Args:
        plan: the plan that runs (for node names and the tree's shape).
    """

    def __init__(self, plan: PlanSpec) -> None:
        self._plan = plan
        self._parent: dict[str, str] = {}
        self._nodes: dict[str, NodeSpec] = {}
        if plan.tree is not None:
            self._parent[plan.tree.id] = ROOT_ID
            for _, node in plan.walk():
                self._nodes[node.id] = node
                self._parent.update((child.id, node.id) for child in node.children)
        self._results: dict[str, list[tuple[int, Status, str]]] = {}
        self._lock = threading.Lock()

    def __call__(self, event: Event) -> None:
        if isinstance(event, StatusChanged) and event.new in _RESULTS:
            with self._lock:
                entry = (event.tick, event.new, event.message)
                self._results.setdefault(event.node_id, []).append(entry)

    def caught(self) -> list[CaughtFailure]:
        """The failures that some ancestor carried on past, in the order they first happened.

        A node that failed only because a child failed is not listed again: the child is.
        """
        with self._lock:
            results = {node: list(entries) for node, entries in self._results.items()}
        grouped: dict[tuple[str, str], list[str]] = {}
        for node_id, entries in results.items():
            for tick, status, message in entries:
                if status is not Status.FAILURE or self._child_failed(results, node_id, tick):
                    continue
                catcher = self._catcher(results, node_id, tick)
                if catcher is not None:
                    grouped.setdefault((node_id, catcher), []).append(message)
        first_tick = {node: entries[0][0] for node, entries in results.items()}
        order = sorted(grouped, key=lambda key: first_tick.get(key[0], 0))
        return [
            CaughtFailure(
                self._name(node), grouped[(node, by)][-1], self._name(by), len(grouped[(node, by)])
            )
            for node, by in order
        ]

    def cause(self) -> str:
        """Why the run failed, as a user reads it: the last failure no ancestor carried on
        past that is not only a child's failure, "pick cup failed: no cup in view" ("" when
        none: the run did not fail). A composite's own words ("every option failed") are
        left out: the leaf under it says more.
        """
        with self._lock:
            results = {node: list(entries) for node, entries in self._results.items()}
        last: tuple[int, str, str] | None = None
        for node_id, entries in results.items():
            if node_id == ROOT_ID:  # the root fails only when the plan's top node did
                continue
            for tick, status, message in entries:
                if status is not Status.FAILURE or self._child_failed(results, node_id, tick):
                    continue
                if self._catcher(results, node_id, tick) is None and (
                    last is None or tick >= last[0]
                ):
                    last = (tick, node_id, message)
        if last is None:
            return ""
        _, node_id, message = last
        return f"{self._name(node_id)} failed" + (f": {message}" if message else "")

    def _child_failed(
        self, results: dict[str, list[tuple[int, Status, str]]], node: str, tick: int
    ) -> bool:
        spec = self._nodes.get(node)
        children = spec.children if spec is not None else []
        return any(
            entry[0] == tick and entry[1] is Status.FAILURE
            for child in children
            for entry in results.get(child.id, [])
        )

    def _catcher(
        self, results: dict[str, list[tuple[int, Status, str]]], node: str, tick: int
    ) -> str | None:
        """The nearest ancestor whose next result at or after ``tick`` was not a failure."""
        ancestor = self._parent.get(node)
        while ancestor is not None:
            later = [entry for entry in results.get(ancestor, []) if entry[0] >= tick]
            if not later or later[0][1] is not Status.FAILURE:
                return ancestor
            tick = later[0][0]
            ancestor = self._parent.get(ancestor)
        return None  # it failed the whole run: not caught

    def _name(self, node_id: str) -> str:
        if node_id == ROOT_ID:
            return f"the plan's root (runs {self._plan.run_policy.value.replace('_', ' ')})"
        node = self._nodes.get(node_id)
        if node is None:
            return node_id
        if node.kind is NodeKind.OPERATION or not node.name:
            return node.label
        kind = node.kind.value.replace("_", " ").capitalize()
        return f"{kind} '{node.name}'"
