"""Subtree instances: their ports, their scopes and the runtime node that runs one.

An instance (``NodeKind.SUBTREE``) runs an embedded subtree definition the way
BehaviorTree.CPP's SubTree node does with port remapping: when it starts, each declared input
is copied into the instance's own scope (from its fixed value, or from the name it is bound to
outside); when the inside succeeds, each declared output bound to an outside name is copied
out. Every other name inside lives in the instance's scope, so two instances of one subtree
never write each other's values; the subtree's ``shared_names`` are the ones that cross on
purpose.

The scope is a prefix on the one blackboard of the tree (``Transfer 4-hole#ab12cd/PICK``), so
the blackboard panel, the trace and the write listeners see the inside like everything else.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from engine.context import TreeContext
from engine.decorators import Decorator
from engine.operations import Direction, OperationKind, OperationManifest, PortSpec
from engine.spec import NodeKind, NodeSpec, PlanSpec, SubtreeRef, SubtreeSpec
from engine.status import RUNNING, SUCCESS, Status
from engine.types import ParamType

__all__ = [
    "Scope",
    "SubtreeInstance",
    "instance_manifest",
    "RuntimeNode",
    "runtime_nodes",
    "runtime_paths",
    "ROOT_SCOPE",
]


def instance_manifest(subtree: SubtreeSpec) -> OperationManifest:
    """The ports of an instance, as a manifest: declared inputs IN, declared outputs OUT.

    Validation and the inspector treat an instance's bindings exactly like an operation's.
    """
    ports = [
        PortSpec(p.name, (ParamType(p.type),), Direction.IN, default=p.default, doc=p.doc)
        for p in subtree.inputs
    ]
    ports += [
        PortSpec(p.name, (ParamType(p.type),), Direction.OUT, doc=p.doc) for p in subtree.outputs
    ]
    return OperationManifest(
        id=f"subtree:{subtree.name}",
        kind=OperationKind.ACTION,
        doc=subtree.description,
        capability="library",
        ports=tuple(ports),
    )


@dataclass(frozen=True)
class RuntimeNode:
    """A node of the tree a plan builds, found from the plan: the insides of instances too.

    Attributes:
        spec: the node's spec (inside an instance, the subtree definition's node).
        path: where it is, ``Kitting/Handoff[0]/...``.
        parent: the runtime id of its parent ("" for the plan's top node).
        label: what the Instructor calls it; inside an instance the instance's label first,
            ``Pick cup > grasp CUP``.
    """

    spec: NodeSpec
    path: str
    parent: str
    label: str


def runtime_nodes(plan: PlanSpec) -> dict[str, RuntimeNode]:
    """Runtime node id -> :class:`RuntimeNode`, the insides of instances included (their
    ids are ``"<instance id>/<inner id>"``, as :meth:`Scope.node_id` makes them).
    """
    nodes: dict[str, RuntimeNode] = {}
    # (top node, id prefix, its path, its parent's runtime id, label prefix, subtrees open)
    stack: list[tuple[NodeSpec, str, str, str, str, tuple[SubtreeRef, ...]]] = []
    if plan.tree is not None:
        stack.append((plan.tree, "", "", "", "", ()))
    while stack:
        top, prefix, base, parent, labels, seen = stack.pop()
        parents = {id(top): parent}
        for path, node in top.walk(base):
            runtime_id = f"{prefix}{node.id}"
            nodes[runtime_id] = RuntimeNode(node, path, parents[id(node)], f"{labels}{node.label}")
            parents.update((id(child), runtime_id) for child in node.children)
            inner = (
                plan.subtree(node.subtree)
                if node.kind is NodeKind.SUBTREE and node.subtree
                else None
            )
            if inner is not None and inner.ref not in seen:
                stack.append(
                    (
                        inner.tree,
                        f"{runtime_id}/",
                        f"{path}/{inner.tree.label}",
                        runtime_id,
                        f"{labels}{node.label} > ",
                        (*seen, inner.ref),
                    )
                )
    return nodes


def runtime_paths(plan: PlanSpec) -> dict[str, str]:
    """Runtime node id -> path, the insides of instances included (``Kitting/Handoff[0]/...``).

    Status events name runtime ids; this tells a reader where each one is.
    """
    return {runtime_id: node.path for runtime_id, node in runtime_nodes(plan).items()}


@dataclass(frozen=True)
class Scope:
    """Where the names and ids of the nodes being built live.

    Attributes:
        ids: prefix of the runtime ids ("" at the top, ``"<instance id>/"`` inside).
        names: prefix of the private blackboard names ("" at the top).
        shared: names that resolve in the enclosing scope instead of this one.
        outer: the enclosing scope (None at the top).
        stack: the subtrees being expanded, outermost first (a subtree may not hold itself).
    """

    ids: str = ""
    names: str = ""
    shared: frozenset[str] = frozenset()
    outer: Scope | None = None
    stack: tuple[SubtreeRef, ...] = ()

    def key(self, name: str) -> str:
        """The blackboard key of ``name`` as the nodes of this scope use it (``@name``: the
        top-level entry, as BehaviorTree.CPP's root blackboard).
        """
        if name.startswith("@"):
            return name[1:]
        if self.outer is not None and name in self.shared:
            return self.outer.key(name)
        return f"{self.names}{name}"

    def node_id(self, spec_id: str) -> str:
        return f"{self.ids}{spec_id}"

    def inside(self, instance: NodeSpec, subtree: SubtreeSpec) -> Scope:
        """The scope of the nodes inside ``instance``."""
        label = (instance.name or subtree.name).replace("/", "_")
        return Scope(
            ids=f"{self.node_id(instance.id)}/",
            names=f"{self.names}{label}#{instance.id[:6]}/",
            shared=frozenset(subtree.shared_names),
            outer=self,
            stack=(*self.stack, subtree.ref),
        )


ROOT_SCOPE = Scope()


@dataclass(frozen=True)
class InputCopy:
    """One input copied in at start: into ``key`` from ``source`` (an outside key) or ``value``."""

    key: str
    source: str | None = None
    value: Any = None


class SubtreeInstance(Decorator):
    """Runs the inside of a subtree instance with its inputs copied in and outputs copied out.

    Args:
        ctx: the tree's context.
        node_id: the instance's runtime id.
        name: its label.
        inputs: what to copy in when it starts.
        outputs: (inside key, outside key) pairs copied out on SUCCESS.
    """

    kind = "subtree"

    def __init__(
        self,
        ctx: TreeContext,
        node_id: str,
        name: str,
        inputs: Sequence[InputCopy],
        outputs: Sequence[tuple[str, str]],
    ) -> None:
        super().__init__(ctx, node_id, name)
        self._inputs = tuple(inputs)
        self._outputs = tuple(outputs)
        self._started = False

    def update(self) -> Status:
        if not self._started:
            problem = self._copy_in()
            if problem:
                return self.fail(problem)
            self._started = True
        status = self.child.tick()
        if status is SUCCESS:
            problem = self._copy_out()
            if problem:
                return self.fail(problem)
            self.message = self.child.message
        elif status is not RUNNING:
            self.message = self.child.message
        return status

    def _copy_in(self) -> str:
        board = self.ctx.blackboard
        for copy in self._inputs:
            value = copy.value
            if copy.source is not None:
                value = board.get(copy.source, None)
                if value is None:
                    return f"parameter {copy.source!r} (for {copy.key!r}) has no value yet"
            try:
                self.ctx.write(copy.key, value, self.id)
            except Exception as exc:  # a wrong type: the instance fails, naming the input
                return f"cannot pass {copy.key!r} in: {exc}"
        return ""

    def _copy_out(self) -> str:
        board = self.ctx.blackboard
        for inside, outside in self._outputs:
            value = board.get(inside, None)
            if value is None:
                return f"the subtree wrote no value for its output {inside!r}"
            try:
                self.ctx.write(outside, value, self.id)
            except Exception as exc:
                return f"cannot pass {inside!r} out to {outside!r}: {exc}"
        return ""

    def on_reset(self) -> None:
        self._started = False
