"""Spec + operation registry -> runnable tree.

The builder assumes a valid plan (see :mod:`engine.validation`) but never trusts it: what it
cannot build raises :class:`BuildError` naming the node's path.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from engine.blackboard import Blackboard, BlackboardError
from engine.blackboard_leaves import (
    AlwaysFailure,
    AlwaysSuccess,
    SetBlackboard,
    UnsetBlackboard,
)
from engine.catch import Catch
from engine.composites import (
    AsyncFallback,
    AsyncSequence,
    Parallel,
    ParallelPolicy,
    ReactiveSelector,
    ReactiveSequence,
    Selector,
    Sequence,
    SequenceWithMemory,
)
from engine.conditions import Condition, NodeConditions
from engine.context import TreeContext
from engine.controls import IfThenElse, ParallelAll, Switch, TryCatch, WhileDoElse
from engine.decorators import (
    Delay,
    Enforce,
    ForceFailure,
    ForceSuccess,
    Inverter,
    Iterator,
    KeepRunningUntilFailure,
    Precondition,
    Repeat,
    Retry,
    RunOnce,
    Timeout,
)
from engine.entry_updates import SkipUnlessUpdated, WaitValueUpdate, WasEntryUpdated
from engine.error_types import parse_error_types
from engine.errors import EngineError
from engine.instances import ROOT_SCOPE, InputCopy, Scope, SubtreeInstance
from engine.kinds import settings_of
from engine.leaves import OperationLeaf, ScriptLeaf, Wait
from engine.node import Node
from engine.operations import Direction, OperationNotFound, OperationSource
from engine.queue_loop import Loop
from engine.script import ScriptSyntaxError, parse_script
from engine.spec import KIND_CATEGORY, Category, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.tree import BehaviorTree, Root
from engine.types import with_article

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
    NodeKind.SEQUENCE_WITH_MEMORY: SequenceWithMemory,
    NodeKind.ASYNC_SEQUENCE: AsyncSequence,
    NodeKind.ASYNC_FALLBACK: AsyncFallback,
    NodeKind.IF_THEN_ELSE: IfThenElse,
    NodeKind.WHILE_DO_ELSE: WhileDoElse,
    NodeKind.KEEP_RUNNING_UNTIL_FAILURE: KeepRunningUntilFailure,
    NodeKind.ALWAYS_SUCCESS: AlwaysSuccess,
    NodeKind.ALWAYS_FAILURE: AlwaysFailure,
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


def _logic_node(spec: NodeSpec, ctx: TreeContext, node_id: str, scope: Scope) -> Node:
    simple = _SIMPLE.get(spec.kind)
    if simple is not None:
        return simple(ctx, node_id, spec.label)
    # The same checks as validation: a Repeat without a count must not become an endless loop.
    cfg = settings_of(spec.kind, spec.params)
    label = spec.label
    factories: dict[NodeKind, Callable[[], Node]] = {
        NodeKind.PARALLEL: lambda: Parallel(
            ctx,
            node_id,
            label,
            ParallelPolicy(_policy(cfg["success"]), _policy(cfg["failure"])),
        ),
        NodeKind.ITERATOR: lambda: Iterator(
            ctx, node_id, label, _whole_or_none(cfg["count"]), float(cfg["timeout"]) or None
        ),
        NodeKind.ENFORCE: lambda: Enforce(
            ctx, node_id, label, _whole_or_none(cfg["count"]), float(cfg["timeout"]) or None
        ),
        NodeKind.REPEAT: lambda: Repeat(ctx, node_id, label, int(cfg["count"])),
        NodeKind.RETRY: lambda: Retry(ctx, node_id, label, int(cfg["count"])),
        NodeKind.TIMEOUT: lambda: Timeout(ctx, node_id, label, float(cfg["seconds"])),
        NodeKind.WAIT: lambda: Wait(ctx, node_id, label, float(cfg["seconds"])),
        NodeKind.CATCH: lambda: Catch(
            ctx, node_id, label, parse_error_types(str(cfg["errors"])), str(cfg["error"])
        ),
        NodeKind.SCRIPT: lambda: ScriptLeaf(ctx, node_id, label, cfg["code"], key=scope.key),
        NodeKind.SCRIPT_CONDITION: lambda: ScriptLeaf(
            ctx, node_id, label, cfg["code"], condition=True, key=scope.key
        ),
        **_builtin_factories(cfg, ctx, node_id, label, scope),
    }
    return factories[spec.kind]()


def _builtin_factories(
    cfg: dict[str, Any], ctx: TreeContext, node_id: str, label: str, scope: Scope
) -> dict[NodeKind, Callable[[], Node]]:
    """The BehaviorTree.CPP built-ins that take settings."""
    return {
        NodeKind.PARALLEL_ALL: lambda: ParallelAll(ctx, node_id, label, int(cfg["max_failures"])),
        NodeKind.SWITCH: lambda: Switch(
            ctx,
            node_id,
            label,
            cfg["variable"],
            tuple(cfg[name] for name in sorted(cfg) if name.startswith("case_")),
            key=scope.key,
        ),
        NodeKind.TRY_CATCH: lambda: TryCatch(ctx, node_id, label, cfg["catch_on_halt"] == "true"),
        NodeKind.DELAY: lambda: Delay(ctx, node_id, label, float(cfg["seconds"])),
        NodeKind.RUN_ONCE: lambda: RunOnce(ctx, node_id, label, cfg["then_skip"] == "true"),
        NodeKind.PRECONDITION: lambda: Precondition(
            ctx, node_id, label, cfg["if"], Status(cfg["else"]), key=scope.key
        ),
        NodeKind.LOOP: lambda: Loop(
            ctx,
            node_id,
            label,
            cfg["queue"],
            cfg["value"],
            cfg["type"],
            Status(cfg["if_empty"]),
            key=scope.key,
        ),
        NodeKind.SET_BLACKBOARD: lambda: SetBlackboard(
            ctx, node_id, label, cfg["value"], cfg["output_key"], key=scope.key
        ),
        NodeKind.UNSET_BLACKBOARD: lambda: UnsetBlackboard(
            ctx, node_id, label, cfg["key"], key=scope.key
        ),
        NodeKind.SKIP_UNLESS_UPDATED: lambda: SkipUnlessUpdated(
            ctx, node_id, label, cfg["entry"], key=scope.key
        ),
        NodeKind.WAIT_VALUE_UPDATE: lambda: WaitValueUpdate(
            ctx, node_id, label, cfg["entry"], key=scope.key
        ),
        NodeKind.WAS_ENTRY_UPDATED: lambda: WasEntryUpdated(
            ctx, node_id, label, cfg["entry"], key=scope.key
        ),
    }


def _operation_leaf(spec: NodeSpec, build: _Build, path: str, scope: Scope) -> Node:
    source = build.source
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
                outputs[port.name] = scope.key(binding.ref)
            continue
        if binding is None:
            if port.default is None:
                raise BuildError(path, f"parameter {port.name!r} is not set")
            fixed[port.name] = port.default
        elif binding.ref is not None:
            refs[port.name] = scope.key(binding.ref)
        else:
            fixed[port.name] = binding.value
    return OperationLeaf(
        build.ctx,
        scope.node_id(spec.id),
        spec.label,
        manifest.kind,
        operation,
        fixed,
        refs,
        outputs,
        ports=manifest.inputs,
        capability=manifest.capability,
    )


@dataclass(frozen=True)
class _Build:
    """What every node of one build needs."""

    plan: PlanSpec
    ctx: TreeContext
    source: OperationSource
    scopes: dict[str, Callable[[str], str]] = field(default_factory=dict)


def _instance(spec: NodeSpec, build: _Build, path: str, scope: Scope) -> Node:
    """An instance: its inside built in a scope of its own, inputs in and outputs out."""
    if spec.subtree is None:
        raise BuildError(path, "a subtree instance needs the subtree it runs")
    subtree = build.plan.subtree(spec.subtree)
    if subtree is None:
        raise BuildError(
            path, f"the plan holds no subtree {spec.subtree.id!r} version {spec.subtree.version}"
        )
    if subtree.ref in scope.stack:
        raise BuildError(path, f"the subtree {subtree.name!r} holds an instance of itself")
    if spec.children:
        raise BuildError(path, "a subtree instance cannot have children")
    inner = scope.inside(spec, subtree)
    inputs: list[InputCopy] = []
    for port in subtree.inputs:
        binding = spec.params.get(port.name)
        key = inner.key(port.name)
        build.ctx.blackboard.declare(key, port.type)
        if binding is not None and binding.ref is not None:
            inputs.append(InputCopy(key, source=scope.key(binding.ref)))
        elif binding is not None and binding.value is not None:
            inputs.append(InputCopy(key, value=binding.value))
        elif port.default is not None:
            inputs.append(InputCopy(key, value=port.default))
        else:
            raise BuildError(path, f"input {port.name!r} of {subtree.name!r} is not set")
    outputs = [
        (inner.key(port.name), scope.key(binding.ref))
        for port in subtree.outputs
        if (binding := spec.params.get(port.name)) is not None and binding.ref
    ]
    node = SubtreeInstance(build.ctx, scope.node_id(spec.id), spec.label, inputs, outputs)
    _add_conditions(node, spec, build.ctx, path, scope)
    node.set_children([_build_node(subtree.tree, build, f"{path}/{subtree.name}", inner)])
    return node


def _add_conditions(node: Node, spec: NodeSpec, ctx: TreeContext, path: str, scope: Scope) -> None:
    """The node's pre- and post-conditions, run in the scope the node is in."""
    if not spec.conditions:
        return
    for condition, text in spec.conditions.items():
        try:
            parse_script(text) if text.strip() else None
        except ScriptSyntaxError as exc:
            what = Condition(condition).value.replace("_", " ")
            raise BuildError(path, f"its {what} condition is not a script: {exc}") from exc
    conditions = NodeConditions(spec.conditions, ctx.blackboard, key=scope.key, writer=node.id)
    node.conditions = conditions or None


def _build_node(spec: NodeSpec, build: _Build, path: str, scope: Scope) -> Node:
    if scope.outer is not None:  # inside an instance: names in its scope (the debugger's)
        build.scopes[scope.node_id(spec.id)] = scope.key
    try:
        if spec.kind is NodeKind.SUBTREE:
            return _instance(spec, build, path, scope)
        if spec.kind is NodeKind.OPERATION:
            node = _operation_leaf(spec, build, path, scope)
        else:
            node = _logic_node(spec, build.ctx, scope.node_id(spec.id), scope)
        _add_conditions(node, spec, build.ctx, path, scope)
        children = [
            _build_node(child, build, f"{path}/{child.label}[{index}]", scope)
            for index, child in enumerate(spec.children)
        ]
        if KIND_CATEGORY[spec.kind] is Category.LEAF:
            if children:
                raise BuildError(path, f"{with_article(spec.kind.value)} node cannot have children")
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
    build = _Build(plan, ctx, source)
    top = _build_node(plan.tree, build, plan.tree.label, ROOT_SCOPE)
    root = Root(ctx, ROOT_ID, plan.name or "root", plan.run_policy, plan.give_up_after)
    root.set_children([top])
    tree = BehaviorTree(root, ctx)
    tree.scopes.update(build.scopes)
    return tree
