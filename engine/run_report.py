"""Why a run failed, and which failures it carried on past: the root causes of a run.

Each failure starts at one node, the first that failed in that attempt (a leaf, or a node
that fails by itself: a Timeout that ran out, a Force failure); the parents that failed
because of it *passed it up*, and the first that did not fail because of it (a Selector
trying its next option, a Retry trying again, a Catch, a root that runs until success)
*caught* it. :class:`FailureLog`, a run listener, keeps every node's results and reports
each root cause with its error type and message, how many times it failed so, the nodes
that passed it up and the node that caught it: "grasp CUP failed 4 times (grasp_failed):
nothing between the fingers; passed up by Retry 'pick'; caught by Selector 'pick or wait'".
A failure nothing caught failed the run: that is the run's cause.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any

from engine.build import ROOT_ID
from engine.error_types import ErrorType
from engine.events import Event, StatusChanged
from engine.failure_words import failed_words, node_title, stopped_words
from engine.instances import runtime_nodes
from engine.spec import NodeKind, PlanSpec
from engine.status import Status
from engine.tree import RunPolicy

__all__ = ["RootCause", "FailureLog"]

_RESULTS = (Status.SUCCESS, Status.FAILURE)
_NAMED_BY_LABEL = (NodeKind.OPERATION, NodeKind.WAIT, NodeKind.SUBTREE)


@dataclass(frozen=True)
class RootCause:
    """A node that started failures (``times`` times, with the same error type and message),
    the nodes that passed them up and the node that caught them.

    Attributes:
        node: what the report calls the node ("grasp CUP", "Pick cup > grasp CUP").
        node_id: its runtime id (inside an instance, "<instance id>/<inner id>").
        message: why it failed.
        error: the error type of its failure ("failed": untyped).
        times: how often it failed so in the run.
        passed_up_by: the nodes that failed because of it, innermost first (the furthest it
            went, when the attempts went different ways).
        caught_by: the node that carried on past it ("": nothing did, the run failed).
        stopped_after: the run ended because its root gave up after this many identical
            failures in a row (0: it did not).
    """

    node: str
    node_id: str
    message: str
    error: str
    times: int
    passed_up_by: tuple[str, ...] = ()
    caught_by: str = ""
    stopped_after: int = 0

    def what(self) -> str:
        """``grasp CUP failed 4 times (grasp_failed): nothing between the fingers``."""
        return failed_words(self.node, self.error, self.message, self.times)

    def describe(self) -> str:
        """What, then the nodes that passed it up and the one that caught it:
        ``... ; passed up by Retry 'pick'; caught by Selector 'pick or wait'``; a run's
        cause that made the root give up starts with "stopped after 5 identical failures in
        a row: ".
        """
        parts = [self.what()]
        if self.passed_up_by:
            parts.append(f"passed up by {', '.join(self.passed_up_by)}")
        if self.caught_by:
            parts.append(f"caught by {self.caught_by}")
        text = "; ".join(parts)
        return f"{stopped_words(self.stopped_after)}: {text}" if self.stopped_after else text

    def tip(self) -> str:
        """What the failed node's tooltip adds to its name: ``grasp_failed: nothing between
        the fingers (4 times); passed up by Retry 'pick'; caught by Selector 'pick or wait'``.
        """
        kind = "" if self.error == ErrorType.FAILED.value else self.error
        parts = [": ".join(part for part in (kind, self.message) if part) or "failed"]
        if self.times > 1:
            parts[0] += f" ({self.times} times)"
        if self.passed_up_by:
            parts.append(f"passed up by {', '.join(self.passed_up_by)}")
        if self.caught_by:
            parts.append(f"caught by {self.caught_by}")
        if self.stopped_after:
            parts.append(f"the run {stopped_words(self.stopped_after)}")
        return "; ".join(parts)

    def as_record(self) -> dict[str, Any]:
        """The fields as a JSON object (a trace keeps them)."""
        return {
            "node": self.node_id,
            "label": self.node,
            "message": self.message,
            "error": self.error,
            "times": self.times,
            "passed_up_by": list(self.passed_up_by),
            "caught_by": self.caught_by,
            "stopped_after": self.stopped_after,
        }

    @classmethod
    def from_record(cls, record: dict[str, Any]) -> RootCause:
        return cls(
            str(record.get("label", record.get("node", ""))),
            str(record.get("node", "")),
            str(record.get("message", "")),
            str(record.get("error", "")),
            int(record.get("times", 1)),
            tuple(str(name) for name in record.get("passed_up_by", [])),
            str(record.get("caught_by", "")),
            int(record.get("stopped_after", 0)),
        )


@dataclass(frozen=True)
class _Result:
    seq: int  # the order results came in (events of one tick are in the order they happened)
    status: Status
    message: str
    error: str


class FailureLog:
    """A run listener that keeps each node's results, then names the root causes of failures.

    Args:
        plan: the plan that runs (for node names and the tree's shape, instances' insides
            too).
    """

    def __init__(self, plan: PlanSpec) -> None:
        self._plan = plan
        self._labels: dict[str, str] = {}
        self._parent: dict[str, str] = {}
        self._children: dict[str, list[str]] = {ROOT_ID: []}
        for runtime_id, node in runtime_nodes(plan).items():
            parent = node.parent or ROOT_ID
            self._parent[runtime_id] = parent
            self._children.setdefault(parent, []).append(runtime_id)
            spec = node.spec
            if spec.kind in _NAMED_BY_LABEL:
                self._labels[runtime_id] = node.label
            else:  # "Pick cup > Retry 'grasp 3 times'"
                prefix = node.label.removesuffix(spec.label)
                self._labels[runtime_id] = prefix + node_title(
                    spec.kind.value, spec.name, leaf=False
                )
        self._results: dict[str, list[_Result]] = {}
        self._seq = 0
        self._lock = threading.Lock()

    def __call__(self, event: Event) -> None:
        if isinstance(event, StatusChanged) and event.new in _RESULTS:
            with self._lock:
                self._seq += 1
                result = _Result(self._seq, event.new, event.message, event.error)
                self._results.setdefault(event.node_id, []).append(result)

    # ------------------------------------------------------------------ reports

    def root_causes(self) -> list[RootCause]:
        """Every root cause of the run, in the order each first failed: the node, its error
        type and message, how often, who passed it up and who caught it. Failures are one
        entry when they started at the same node with the same error type and message; the
        one that failed the run (see :meth:`failed_run`) has no catcher and is passed up to
        the top.
        """
        with self._lock:
            results = {node: list(entries) for node, entries in self._results.items()}
        groups: dict[tuple[str, str, str], list[tuple[tuple[str, ...], str | None]]] = {}
        first: dict[tuple[str, str, str], int] = {}
        for node_id, entries in results.items():
            for result in entries:
                if result.status is Status.FAILURE and not self._passed_up(
                    results, node_id, result
                ):
                    key = (node_id, _typed(result.error), result.message)
                    groups.setdefault(key, []).append(self._way_up(results, node_id, result))
                    first[key] = min(first.get(key, result.seq), result.seq)
        run = self._run_failure(results)
        if run is not None:  # its last failure failed the run (found as an origin above)
            groups.setdefault(run[0], [(run[1], None)])
        causes = []
        for key in sorted(groups, key=lambda k: first.get(k, 0)):
            node_id, error, message = key
            ways = groups[key]
            if run is not None and key == run[0]:
                passed, catcher = run[1], None
            else:
                passed, catcher = max(ways, key=lambda way: (way[1] is None, len(way[0])))
            stopped = 0
            if run is not None and key == run[0] and self._gave_up(results):
                stopped = self._plan.give_up_after
            causes.append(
                RootCause(
                    self._name(node_id),
                    node_id,
                    message,
                    error,
                    len(ways),
                    tuple(self._name(n) for n in passed if n != ROOT_ID),
                    "" if catcher is None else self._name(catcher),
                    stopped,
                )
            )
        return causes

    def failed_run(self) -> RootCause | None:
        """Why the run failed (None when it did not): the node the root's failure started
        at, down through the first failed child in tick order (the first option of a
        Selector that failed, not its fallback), as the root counts identical failures.
        """
        causes = self.root_causes()
        with self._lock:
            results = {node: list(entries) for node, entries in self._results.items()}
        run = self._run_failure(results)
        if run is None:
            return None
        node_id, error, message = run[0]
        return next(
            c for c in causes if (c.node_id, c.error, c.message) == (node_id, error, message)
        )

    def on_the_way(self) -> list[RootCause]:
        """The root causes other than the run's own: the failures it carried on past (each
        with the node that caught it) and those of fallbacks that failed too.
        """
        cause = self.failed_run()
        return [c for c in self.root_causes() if c != cause]

    def cause(self) -> str:
        """Why the run failed, as a user reads it ("" when it did not fail): "grasp CUP
        failed 3 times: nothing between the fingers; passed up by Retry 'pick', Sequence
        'transfer'". A composite's own words ("every option failed") are left out: the node
        the failure started at says more.
        """
        cause = self.failed_run()
        return cause.describe() if cause is not None else ""

    def _run_failure(
        self, results: dict[str, list[_Result]]
    ) -> tuple[tuple[str, str, str], tuple[str, ...]] | None:
        """The (node, error type, message) the run's failure started at and the nodes that
        passed it up, innermost first; None when the run did not fail.
        """
        failures = [r for r in results.get(ROOT_ID, []) if r.status is Status.FAILURE]
        if not failures:
            return None
        node, result, path = ROOT_ID, failures[-1], [ROOT_ID]
        while True:
            child = self._first_failed_child(results, node, result)
            if child is None:
                key = (node, _typed(result.error), result.message)
                return key, tuple(reversed(path[:-1]))
            node, result = child
            path.append(node)

    def _first_failed_child(
        self, results: dict[str, list[_Result]], node: str, result: _Result
    ) -> tuple[str, _Result] | None:
        """The first child in tick order whose last result before ``result`` of ``node`` is
        a failure of the same activation (after the node's own result before), with it.
        """
        earlier = [own.seq for own in results.get(node, []) if own.seq < result.seq]
        since = max(earlier, default=0)
        for child in self._children.get(node, []):
            before = [e for e in results.get(child, []) if since < e.seq < result.seq]
            if before and before[-1].status is Status.FAILURE:
                return child, before[-1]
        return None

    def _gave_up(self, results: dict[str, list[_Result]]) -> bool:
        """Whether the root failed by giving up (it runs until success: the only way)."""
        return self._plan.run_policy is RunPolicy.UNTIL_SUCCESS and any(
            r.status is Status.FAILURE for r in results.get(ROOT_ID, [])
        )

    # ------------------------------------------------------------------ the tree's shape

    def _passed_up(self, results: dict[str, list[_Result]], node: str, result: _Result) -> bool:
        """Whether the node failed because a child did: the last result of its children
        before this failure is a failure, with no result of the node itself in between.
        """
        latest: _Result | None = None
        for child in self._children.get(node, []):
            for entry in results.get(child, []):
                if entry.seq < result.seq and (latest is None or entry.seq > latest.seq):
                    latest = entry
        if latest is None or latest.status is not Status.FAILURE:
            return False
        return not any(latest.seq < own.seq < result.seq for own in results.get(node, []))

    def _way_up(
        self, results: dict[str, list[_Result]], node: str, result: _Result
    ) -> tuple[tuple[str, ...], str | None]:
        """The ancestors that passed a failure up, innermost first, and the one that caught
        it (None: the root passed it up, the run failed).
        """
        passed: list[str] = []
        seq = result.seq
        while node != ROOT_ID:
            parent = self._parent.get(node, ROOT_ID)
            after = [entry for entry in results.get(parent, []) if entry.seq > seq]
            if not after or after[0].status is not Status.FAILURE:
                return tuple(passed), parent
            if any(
                seq < entry.seq < after[0].seq
                for child in self._children.get(parent, [])
                for entry in results.get(child, [])
            ):  # a child had another result first: the parent went on past this failure
                return tuple(passed), parent
            passed.append(parent)
            node, seq = parent, after[0].seq
        return tuple(passed), None

    def _name(self, node_id: str) -> str:
        if node_id == ROOT_ID:
            return f"the plan's root (runs {self._plan.run_policy.value.replace('_', ' ')})"
        return self._labels.get(node_id, node_id)


def _typed(error: str) -> str:
    return error or ErrorType.FAILED.value
