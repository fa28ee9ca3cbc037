"""The benchmark trees of ``bench/trees/trees.json``, built in our engine and in py_trees.

The file holds flat node tables (pre-order, node 0 the root) plus, per tree, the leaf
behaviour, how to measure it and the counts a reference interpreter with memory semantics
produced. This module loads it and builds each tree in both engines with the same semantics
(memory Sequences/Fallbacks, a synchronising all-must-succeed Parallel).

Our leaves are real :class:`~engine.leaves.OperationLeaf` nodes running tiny operations (what
a plan's leaves are); the root we tick is the file's node 0 itself, without a
:class:`~engine.tree.Root` above it, so that both engines run exactly the file's nodes.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import py_trees

from engine.composites import Parallel, ParallelPolicy, Selector, Sequence
from engine.context import TreeContext
from engine.decorators import ForceSuccess, Inverter
from engine.leaves import OperationLeaf
from engine.node import Node
from engine.operations import Job, OperationCall, OperationKind
from engine.status import RUNNING, Status

__all__ = [
    "BenchError",
    "BuiltTree",
    "TreeDef",
    "build_ours",
    "build_py_trees",
    "default_trees_path",
    "load_trees",
    "type_name",
    "ENGINES",
]

_LEAF_TYPES = ("Condition", "Action")
# The file's inner node types in each engine (our Parallel takes a policy: built apart).
_OUR_CLASSES: dict[str, type[Node]] = {
    "Sequence": Sequence,
    "Fallback": Selector,
    "Inverter": Inverter,
    "ForceSuccess": ForceSuccess,
}
_PT_CLASSES: dict[str, Any] = {
    "Sequence": py_trees.composites.Sequence,
    "Fallback": py_trees.composites.Selector,
    "Parallel": py_trees.composites.Parallel,
    "Inverter": py_trees.decorators.Inverter,
    "ForceSuccess": py_trees.decorators.FailureIsSuccess,
}


class BenchError(Exception):
    """The trees file is unreadable, or a built tree does not behave as the file expects."""


@dataclass(frozen=True)
class TreeDef:
    """One tree of the file, as read (node dicts are the file's own)."""

    id: str
    key: str
    measure: str  # "per_tick" or "until_done"
    nodes: tuple[dict[str, Any], ...]
    leaf_behaviour: dict[str, dict[str, Any]]
    expected: dict[str, Any]


@dataclass(frozen=True)
class BuiltTree:
    """A tree built in one engine, with the calls the bench drives it by.

    Attributes:
        engine: "ours" or "py_trees".
        root: the engine's node for the file's node 0.
        nodes: every node of the tree (for the counting wrappers).
        tick_once: one root tick; returns the root's status name ("SUCCESS", ...).
        restart: makes the next tick start a fresh run (ours: reset the root, because our
            nodes latch; py_trees: nothing, its composites re-initialise on re-entry).
        loop: ``loop(n)`` runs n per-tick measurements (ours: tick + reset; py_trees: tick).
        run: ticks until the root finishes, then restarts; returns the number of ticks.
    """

    engine: str
    root: Any
    nodes: tuple[Any, ...]
    tick_once: Callable[[], str]
    restart: Callable[[], None]
    loop: Callable[[int], None]
    run: Callable[[], int]


def default_trees_path() -> Path:
    """``bench/trees/trees.json``, the copy kept in this repository (see its README)."""
    return Path(__file__).resolve().parent / "trees" / "trees.json"


def load_trees(path: Path) -> list[TreeDef]:
    """Read and check the trees file; raises BenchError with the file and what is wrong."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise BenchError(f"{path}: cannot read the trees file: {exc}") from exc
    if data.get("format") != "bt-bench-trees" or data.get("version") != 1:
        raise BenchError(f"{path}: expected format 'bt-bench-trees' version 1")
    try:
        trees = _tree_defs(data)
    except (KeyError, TypeError, ValueError) as exc:
        raise BenchError(f"{path}: malformed tree: {exc!r}") from exc
    if not trees:
        raise BenchError(f"{path}: no trees")
    return trees


def _tree_defs(data: dict[str, Any]) -> list[TreeDef]:
    trees = []
    for raw in data.get("trees", []):
        nodes = tuple(raw["nodes"])
        for index, node in enumerate(nodes):
            if node.get("id") != index:
                raise ValueError(f"tree {raw['id']}: node {index} has id {node.get('id')}")
        trees.append(
            TreeDef(
                raw["id"], raw["key"], raw["measure"], nodes, raw["leaf_behaviour"], raw["expected"]
            )
        )
    return trees


# ---------------------------------------------------------------------- our engine


class _Returns:
    """An operation that finishes at once with a fixed answer."""

    __slots__ = ("answer",)

    def __init__(self, answer: bool) -> None:
        self.answer = Job.answer(answer)  # a finished job, shared: made once

    def start(self, call: OperationCall) -> Job:
        return self.answer


class _CountdownJob(Job):
    """RUNNING for ``ticks`` polls, then ``then``."""

    def __init__(self, ticks: int, then: Status) -> None:
        super().__init__()
        self._left = ticks
        self._then = then

    def poll(self) -> Status:
        if self._left:
            self._left -= 1
            return RUNNING
        return self._then


class _RunsTicks:
    """An operation whose job runs for a number of ticks."""

    __slots__ = ("then", "ticks")

    def __init__(self, ticks: int, then: Status) -> None:
        self.ticks = ticks
        self.then = then

    def start(self, call: OperationCall) -> Job:
        return _CountdownJob(self.ticks, self.then)


def _leaf_rule(tree: TreeDef, node_type: str) -> tuple[str, int]:
    """(final status name, RUNNING ticks before it) of a leaf type."""
    rule = tree.leaf_behaviour[node_type]
    if "returns" in rule:
        final, ticks = rule["returns"], 0
    else:
        final, ticks = rule["then"], int(rule["running_ticks"])
    if final not in ("SUCCESS", "FAILURE"):
        raise BenchError(f"tree {tree.id}: unsupported leaf behaviour {rule}")
    return final, ticks


def _our_node(tree: TreeDef, raw: dict[str, Any], ctx: TreeContext) -> Node:
    node_id, name, node_type = str(raw["id"]), raw["name"], raw["type"]
    if node_type in _LEAF_TYPES:
        final, ticks = _leaf_rule(tree, node_type)
        operation: _Returns | _RunsTicks
        if ticks:
            operation = _RunsTicks(ticks, Status(final))
        else:
            operation = _Returns(final == "SUCCESS")
        kind = OperationKind.CONDITION if node_type == "Condition" else OperationKind.ACTION
        return OperationLeaf(ctx, node_id, name, kind, operation)
    if node_type == "Parallel":
        return Parallel(ctx, node_id, name, _our_policy(tree, raw.get("params", {})))
    if node_type not in _OUR_CLASSES:
        raise BenchError(f"tree {tree.id}: unknown node type {node_type!r}")
    return _OUR_CLASSES[node_type](ctx, node_id, name)


def _our_policy(tree: TreeDef, params: dict[str, Any]) -> ParallelPolicy:
    # Our Parallel always synchronises (finished children are not ticked again).
    if params.get("synchronise", True) is not True:
        raise BenchError(f"tree {tree.id}: our Parallel only synchronises")
    return ParallelPolicy(
        params.get("success_threshold", "all"), params.get("failure_threshold", 1)
    )


def build_ours(tree: TreeDef) -> BuiltTree:
    """The tree in our engine; its root is the file's node 0 (no Root node above it)."""
    ctx = TreeContext()
    nodes = [_our_node(tree, raw, ctx) for raw in tree.nodes]
    for raw, node in zip(tree.nodes, nodes, strict=True):
        if "children" in raw:
            node.set_children([nodes[i] for i in raw["children"]])
    root = nodes[0]

    def tick_once() -> str:
        return root.tick().value

    def loop(n: int) -> None:
        tick, reset = root.tick, root.reset
        for _ in range(n):
            tick()
            reset()

    def run() -> int:
        tick = root.tick
        ticks = 1
        while tick() is RUNNING:
            ticks += 1
        root.reset()
        return ticks

    return BuiltTree("ours", root, tuple(nodes), tick_once, root.reset, loop, run)


# ---------------------------------------------------------------------- py_trees


class _PtReturns(py_trees.behaviour.Behaviour):
    """A py_trees leaf that returns a fixed status."""

    def __init__(self, name: str, file_type: str, status: py_trees.common.Status) -> None:
        super().__init__(name)
        self.file_type = file_type
        self._answer = status

    def update(self) -> py_trees.common.Status:
        return self._answer


class _PtRunsTicks(py_trees.behaviour.Behaviour):
    """A py_trees leaf that is RUNNING for ``ticks`` ticks after (re)start, then ``then``."""

    def __init__(self, name: str, file_type: str, ticks: int, then: py_trees.common.Status) -> None:
        super().__init__(name)
        self.file_type = file_type
        self._ticks = ticks
        self._then = then
        self._left = ticks

    def initialise(self) -> None:
        self._left = self._ticks

    def update(self) -> py_trees.common.Status:
        if self._left:
            self._left -= 1
            return py_trees.common.Status.RUNNING
        return self._then


def _pt_node(tree: TreeDef, raw: dict[str, Any], built: dict[int, Any]) -> Any:
    name, node_type = raw["name"], raw["type"]
    children = [built[i] for i in raw.get("children", ())]
    if node_type in _LEAF_TYPES:
        final, ticks = _leaf_rule(tree, node_type)
        status = py_trees.common.Status(final)
        if ticks:
            return _PtRunsTicks(name, node_type, ticks, status)
        return _PtReturns(name, node_type, status)
    if node_type in ("Sequence", "Fallback"):
        return _PT_CLASSES[node_type](name, memory=True, children=children)
    if node_type == "Parallel":
        params = raw.get("params", {})
        if (
            params.get("success_threshold", "all") != "all"
            or params.get("failure_threshold", 1) != 1
        ):
            raise BenchError(
                f"tree {tree.id}: only the all/1 Parallel policy is mapped to py_trees"
            )
        policy = py_trees.common.ParallelPolicy.SuccessOnAll(
            synchronise=bool(params.get("synchronise", True))
        )
        return py_trees.composites.Parallel(name, policy=policy, children=children)
    if node_type not in ("Inverter", "ForceSuccess"):
        raise BenchError(f"tree {tree.id}: unknown node type {node_type!r}")
    return _PT_CLASSES[node_type](name=name, child=children[0])


def build_py_trees(tree: TreeDef) -> BuiltTree:
    """The tree in py_trees (memory composites); ticked with ``root.tick_once()``."""
    built: dict[int, Any] = {}
    # Pre-order table: building from the last node up gives every node its children first.
    for raw in reversed(tree.nodes):
        built[raw["id"]] = _pt_node(tree, raw, built)
    root = built[0]
    nodes = tuple(built[i] for i in range(len(tree.nodes)))

    def tick_once() -> str:
        root.tick_once()
        return root.status.value

    def loop(n: int) -> None:
        tick = root.tick_once
        for _ in range(n):
            tick()

    def run() -> int:
        tick, running = root.tick_once, py_trees.common.Status.RUNNING
        ticks = 0
        while True:
            tick()
            ticks += 1
            if root.status is not running:
                return ticks

    return BuiltTree("py_trees", root, nodes, tick_once, _no_restart, loop, run)


def _no_restart() -> None:
    """py_trees composites re-initialise themselves when ticked after finishing."""


#: The engines compared, in report order: (name, builder).
ENGINES: tuple[tuple[str, Callable[[TreeDef], BuiltTree]], ...] = (
    ("ours", build_ours),
    ("py_trees", build_py_trees),
)


def type_name(node: Any) -> str:
    """The file's type name of a built node of either engine."""
    if isinstance(node, OperationLeaf):
        return "Condition" if node.op_kind is OperationKind.CONDITION else "Action"
    if isinstance(node, (_PtReturns, _PtRunsTicks)):
        return node.file_type
    for name, cls in (*_OUR_CLASSES.items(), ("Parallel", Parallel), *_PT_CLASSES.items()):
        if type(node) is cls:
            return name
    return type(node).__name__
