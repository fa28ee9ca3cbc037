"""Spec + operation registry -> runnable tree.

The builder assumes a valid plan (see :mod:`engine.validation`) but never trusts it: what it
cannot build raises :class:`BuildError` naming the node's path.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from engine.blackboard import Blackboard, BlackboardError
from engine.composites import (
    Parallel,
    ParallelPolicy,
    ReactiveSelector,
    ReactiveSequence,
    Selector,
    Sequence,
)
from engine.context import TreeContext
from engine.decorators import (
    Enforce,
    ForceFailure,
    ForceSuccess,
    Inverter,
    Iterator,
    Repeat,
    Retry,
    Timeout,
)
from engine.errors import EngineError
from engine.kinds import settings_of
from engine.leaves import OperationLeaf, Wait
from engine.node import Node
from engine.operations import Direction, OperationNotFound, OperationSource
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.tree import BehaviorTree, Root

__all__ = ["BuildError", "build_tree", "ROOT_ID"]

ROOT_ID = "root"

_SIMPLE: dict[NodeKind, type[Node]] = {
    NodeKind.SEQUENCE: Sequence,
    NodeKind.SELECTOR: Selector,
    NodeKind.REACTIVE_SEQUENCE: ReactiveSequence,
    NodeKind.REACTIVE_SELECTOR: ReactiveSelector,
    NodeKind.INVERTER: Inverter,
    NodeKind.FORCE_SUCCESS: ForceSuccess,
    NodeKind.FORCE_FAILURE: ForceFailure,
}


class BuildError(EngineError):
    """A spec node could not be turned into a runtime node."""

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        super().__init__(f"{path}: {message}")


def _whole_or_none(value: float) -> int | None:
    """A count or limit of 0 means none."""
    return int(value) or None


def _policy(value: str | float) -> str | int:
    return value if isinstance(value, str) else int(value)


def _logic_node(spec: NodeSpec, ctx: TreeContext) -> Node:
    simple = _SIMPLE.get(spec.kind)
    if simple is not None:
        return simple(ctx, spec.id, spec.label)
    # The same checks as validation: a Repeat without a count must not become an endless loop.
    cfg = settings_of(spec.kind, spec.params)
    label = spec.label
    factories: dict[NodeKind, Callable[[], Node]] = {
        NodeKind.PARALLEL: lambda: Parallel(
            ctx,
            spec.id,
            label,
            ParallelPolicy(_policy(cfg["success"]), _policy(cfg["failure"])),
        ),
        NodeKind.ITERATOR: lambda: Iterator(
            ctx, spec.id, label, _whole_or_none(cfg["count"]), float(cfg["timeout"]) or None
        ),
        NodeKind.ENFORCE: lambda: Enforce(
            ctx, spec.id, label, _whole_or_none(cfg["count"]), float(cfg["timeout"]) or None
        ),
        NodeKind.REPEAT: lambda: Repeat(ctx, spec.id, label, int(cfg["count"])),
        NodeKind.RETRY: lambda: Retry(ctx, spec.id, label, int(cfg["count"])),
        NodeKind.TIMEOUT: lambda: Timeout(ctx, spec.id, label, float(cfg["seconds"])),
        NodeKind.WAIT: lambda: Wait(ctx, spec.id, label, float(cfg["seconds"])),
    }
    return factories[spec.kind]()


def _operation_leaf(spec: NodeSpec, ctx: TreeContext, source: OperationSource, path: str) -> Node:
    if not spec.op:
        raise BuildError(path, "an operation node needs an operation id")
    try:
        manifest = source.manifest(spec.op)
        operation = source.create(spec.op)
    except OperationNotFound as exc:
        raise BuildError(path, f"unknown operation {spec.op!r}") from exc
    except Exception as exc:  # a capability's factory failed: a build error, never a crash
        raise BuildError(
            path, f"cannot create operation {spec.op!r}: {type(exc).__name__}: {exc}"
        ) from exc
    fixed: dict[str, Any] = {}
    refs: dict[str, str] = {}
    outputs: dict[str, str] = {}
    for port in manifest.ports:
        binding = spec.params.get(port.name)
        if port.direction is Direction.OUT:
            if binding is not None and binding.ref:
                outputs[port.name] = binding.ref
            continue
        if binding is None:
            if port.default is None:
                raise BuildError(path, f"parameter {port.name!r} is not set")
            fixed[port.name] = port.default
        elif binding.ref is not None:
            refs[port.name] = binding.ref
        else:
            fixed[port.name] = binding.value
    return OperationLeaf(
        ctx, spec.id, spec.label, manifest.kind, operation, fixed, refs, outputs,
        ports=manifest.inputs,
    )  # fmt: skip


def _build_node(spec: NodeSpec, ctx: TreeContext, source: OperationSource, path: str) -> Node:
    try:
        if spec.kind is NodeKind.OPERATION:
            node = _operation_leaf(spec, ctx, source, path)
        else:
            node = _logic_node(spec, ctx)
        children = [
            _build_node(child, ctx, source, f"{path}/{child.label}[{index}]")
            for index, child in enumerate(spec.children)
        ]
        if isinstance(node, (OperationLeaf, Wait)):
            if children:
                raise BuildError(path, f"a {spec.kind.value} node cannot have children")
        else:
            node.set_children(children)
    except BuildError:
        raise
    except (ValueError, KeyError, TypeError) as exc:
        raise BuildError(path, str(exc)) from exc
    return node


def build_tree(
    plan: PlanSpec,
    source: OperationSource,
    *,
    clock: Callable[[], float] | None = None,
    blackboard: Blackboard | None = None,
) -> BehaviorTree:
    """Build the runnable tree of a plan.

    Args:
        plan: the plan; validate it first (``engine.validation.validate_plan``).
        source: where operations come from (a capability registry).
        clock: the tree's clock (default: monotonic seconds); the simulated cell passes
            its simulated time.
        blackboard: start values; by default a fresh one with the plan's parameters.
    """
    if plan.tree is None:
        raise BuildError(plan.name or "plan", "the plan has no tree")
    board = blackboard if blackboard is not None else Blackboard()
    for decl in plan.parameters:
        board.declare(decl.name, decl.type)
        if decl.value is not None:
            try:
                board.set(decl.name, decl.value, "plan")
            except BlackboardError as exc:
                raise BuildError(f"parameters/{decl.name}", str(exc)) from exc
    ctx = TreeContext(board, clock) if clock is not None else TreeContext(board)
    top = _build_node(plan.tree, ctx, source, plan.tree.label)
    root = Root(ctx, ROOT_ID, plan.name or "root", plan.run_policy)
    root.set_children([top])
    return BehaviorTree(root, ctx)
