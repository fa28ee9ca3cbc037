"""The editable plan: plain dataclasses with stable uuid ids (what the editor edits).

The spec is kept apart from the runtime nodes (engine.node and friends): the Instructor and
the files work on the spec, :mod:`engine.build` turns a spec into a runnable tree. A task
plan is a spec whose every operation parameter is bound, to a fixed value ("CUP") or to a
reference to a named parameter that a query writes (CUP_POSE).
"""

from __future__ import annotations

import enum
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from engine.conditions import Condition
from engine.tree import DEFAULT_GIVE_UP_AFTER, RunPolicy
from engine.types import ParamType, Waypoint

__all__ = [
    "NodeKind",
    "Category",
    "SubtreeRef",
    "SubtreePort",
    "SubtreeSpec",
    "KIND_CATEGORY",
    "Binding",
    "NodeSpec",
    "ParameterDecl",
    "NodeLayout",
    "PlanSpec",
    "new_id",
    "RunPolicy",
]


def new_id() -> str:
    """A fresh stable node id (uuid4, hex)."""
    return uuid.uuid4().hex


class Category(str, enum.Enum):
    """How many children a node kind takes: several (composite), one (decorator) or none."""

    COMPOSITE = "composite"
    DECORATOR = "decorator"
    LEAF = "leaf"


class NodeKind(str, enum.Enum):
    """The node kinds a plan can hold; operation leaves name their operation in ``op``."""

    SEQUENCE = "sequence"
    SELECTOR = "selector"
    PARALLEL = "parallel"
    REACTIVE_SEQUENCE = "reactive_sequence"
    REACTIVE_SELECTOR = "reactive_selector"
    # Two children, a body and a handler: the handler runs when the body fails with a
    # caught error type (Rethink Intera's Throw/Catch).
    CATCH = "catch"
    ITERATOR = "iterator"
    ENFORCE = "enforce"
    INVERTER = "inverter"
    REPEAT = "repeat"
    RETRY = "retry"
    TIMEOUT = "timeout"
    FORCE_SUCCESS = "force_success"
    FORCE_FAILURE = "force_failure"
    WAIT = "wait"
    # BehaviorTree.CPP's Script and ScriptCondition: a script of its language (engine.script)
    # run on the blackboard; the condition succeeds when the script's value is true.
    SCRIPT = "script"
    SCRIPT_CONDITION = "script_condition"
    # More of BehaviorTree.CPP 4.10's built-in nodes, under its semantics (engine.builtins).
    SEQUENCE_WITH_MEMORY = "sequence_with_memory"
    ASYNC_SEQUENCE = "async_sequence"
    ASYNC_FALLBACK = "async_fallback"
    PARALLEL_ALL = "parallel_all"
    IF_THEN_ELSE = "if_then_else"
    WHILE_DO_ELSE = "while_do_else"
    # Switch2 .. Switch6: the number of cases is the number of children less the default.
    SWITCH = "switch"
    TRY_CATCH = "try_catch"
    KEEP_RUNNING_UNTIL_FAILURE = "keep_running_until_failure"
    DELAY = "delay"
    RUN_ONCE = "run_once"
    PRECONDITION = "precondition"
    # LoopInt, LoopDouble, LoopBool, LoopString: the element type is a setting.
    LOOP = "loop"
    # Whether an entry was written since the node last looked (its sequence number).
    SKIP_UNLESS_UPDATED = "skip_unless_updated"
    WAIT_VALUE_UPDATE = "wait_value_update"
    WAS_ENTRY_UPDATED = "was_entry_updated"
    ALWAYS_SUCCESS = "always_success"
    ALWAYS_FAILURE = "always_failure"
    SET_BLACKBOARD = "set_blackboard"
    UNSET_BLACKBOARD = "unset_blackboard"
    OPERATION = "operation"
    # An instance of a library subtree: one leaf in the plan's tree, expanded when built.
    SUBTREE = "subtree"


KIND_CATEGORY: dict[NodeKind, Category] = {
    NodeKind.SEQUENCE: Category.COMPOSITE,
    NodeKind.SELECTOR: Category.COMPOSITE,
    NodeKind.PARALLEL: Category.COMPOSITE,
    NodeKind.REACTIVE_SEQUENCE: Category.COMPOSITE,
    NodeKind.REACTIVE_SELECTOR: Category.COMPOSITE,
    NodeKind.CATCH: Category.COMPOSITE,
    NodeKind.ITERATOR: Category.DECORATOR,
    NodeKind.ENFORCE: Category.DECORATOR,
    NodeKind.INVERTER: Category.DECORATOR,
    NodeKind.REPEAT: Category.DECORATOR,
    NodeKind.RETRY: Category.DECORATOR,
    NodeKind.TIMEOUT: Category.DECORATOR,
    NodeKind.FORCE_SUCCESS: Category.DECORATOR,
    NodeKind.FORCE_FAILURE: Category.DECORATOR,
    NodeKind.WAIT: Category.LEAF,
    NodeKind.SCRIPT: Category.LEAF,
    NodeKind.SCRIPT_CONDITION: Category.LEAF,
    NodeKind.SEQUENCE_WITH_MEMORY: Category.COMPOSITE,
    NodeKind.ASYNC_SEQUENCE: Category.COMPOSITE,
    NodeKind.ASYNC_FALLBACK: Category.COMPOSITE,
    NodeKind.PARALLEL_ALL: Category.COMPOSITE,
    NodeKind.IF_THEN_ELSE: Category.COMPOSITE,
    NodeKind.WHILE_DO_ELSE: Category.COMPOSITE,
    NodeKind.SWITCH: Category.COMPOSITE,
    NodeKind.TRY_CATCH: Category.COMPOSITE,
    NodeKind.KEEP_RUNNING_UNTIL_FAILURE: Category.DECORATOR,
    NodeKind.DELAY: Category.DECORATOR,
    NodeKind.RUN_ONCE: Category.DECORATOR,
    NodeKind.PRECONDITION: Category.DECORATOR,
    NodeKind.LOOP: Category.DECORATOR,
    NodeKind.SKIP_UNLESS_UPDATED: Category.DECORATOR,
    NodeKind.WAIT_VALUE_UPDATE: Category.DECORATOR,
    NodeKind.WAS_ENTRY_UPDATED: Category.LEAF,
    NodeKind.ALWAYS_SUCCESS: Category.LEAF,
    NodeKind.ALWAYS_FAILURE: Category.LEAF,
    NodeKind.SET_BLACKBOARD: Category.LEAF,
    NodeKind.UNSET_BLACKBOARD: Category.LEAF,
    NodeKind.OPERATION: Category.LEAF,
    NodeKind.SUBTREE: Category.LEAF,
}


@dataclass(frozen=True)
class Binding:
    """A port's binding: a fixed value or a reference to a named parameter.

    Attributes:
        value: the literal (a Python value of ``type``) when fixed.
        type: the literal's type; files record it so they can be read without a registry.
        ref: the blackboard name when a reference (inputs read it, outputs write it).
    """

    value: Any = None
    type: ParamType | None = None
    ref: str | None = None

    @classmethod
    def fixed(cls, value: Any, ptype: ParamType) -> Binding:
        return cls(value=value, type=ParamType(ptype))

    @classmethod
    def reference(cls, name: str) -> Binding:
        return cls(ref=name)

    @property
    def is_ref(self) -> bool:
        return self.ref is not None


@dataclass
class NodeSpec:
    """One node of the plan tree.

    Attributes:
        kind: what the node is.
        name: the label users gave it (may be empty: the UI shows the kind or operation).
        id: stable uuid, kept through edits, saves and copies within a document.
        op: operation id, for kind OPERATION.
        params: port -> binding; the ports of an operation (its manifest), of a logic
            node kind (engine.kinds.KIND_PORTS: Parallel policy, counts, timeouts, seconds)
            or of a subtree instance (its subtree's declared inputs and outputs).
        children: in tick order.
        subtree: for kind SUBTREE, which subtree (id and version) the instance runs.
        conditions: its pre- and post-conditions (BehaviorTree.CPP's ``_skipIf`` ...), scripts
            run in the node's scope (engine.conditions); any node kind may have them.
    """

    kind: NodeKind
    name: str = ""
    id: str = field(default_factory=new_id)
    op: str | None = None
    params: dict[str, Binding] = field(default_factory=dict)
    children: list[NodeSpec] = field(default_factory=list)
    subtree: SubtreeRef | None = None
    conditions: dict[Condition, str] = field(default_factory=dict)

    @property
    def category(self) -> Category:
        return KIND_CATEGORY[self.kind]

    @property
    def label(self) -> str:
        """What the UI and error messages call this node."""
        return self.name or self.op or self.kind.value

    def walk(self, path: str = "") -> Iterator[tuple[str, NodeSpec]]:
        """(path, node) for this node and all below, depth first in tick order.

        A path is the labels from the top joined by "/", each child with its index:
        ``Transfer/pick[1]/move_to CUP_POSE[3]``.
        """
        here = path or self.label
        yield here, self
        for index, child in enumerate(self.children):
            yield from child.walk(f"{here}/{child.label}[{index}]")

    def find(self, node_id: str) -> NodeSpec | None:
        for _, node in self.walk():
            if node.id == node_id:
                return node
        return None


@dataclass(frozen=True)
class SubtreeRef:
    """Which subtree an instance runs: the subtree's stable id and the version it was made from.

    Attributes:
        id: the subtree's id (stable through renames and new versions).
        version: the version the plan embeds; the library may hold a newer one.
    """

    id: str
    version: int


@dataclass(frozen=True)
class SubtreePort:
    """A declared input or output of a subtree (the ports of its instances).

    Attributes:
        name: the name inside the subtree (a reference its nodes read, or a query writes).
        type: the value type.
        doc: one line for the binding form.
        default: for an input, the value used when an instance leaves it unbound (None:
            the instance must bind it); outputs have none.
    """

    name: str
    type: ParamType
    doc: str = ""
    default: Any = None


@dataclass
class SubtreeSpec:
    """A reusable subtree (paper IV-A): a tree whose open parameters are declared inputs.

    Inside ``tree``, an input is read by reference to its name; a declared output is a name a
    query inside writes. Every other name the tree reads or writes is private to each
    instance (its own scope), except the names in ``shared_names``, which cross scopes on purpose
    (they are the same name in the plan that holds the instance).

    Attributes:
        id: stable id (uuid hex for user subtrees; shipped ones keep a readable one).
        name: what the library and the canvas call it ("Transfer").
        description: what it does, for the library panel.
        version: 1 for the first save, +1 each later save to the library.
        date: when this version was saved, ISO 8601 UTC ("2026-11-24T19:40:00Z").
        tree: the subtree's nodes.
        inputs: declared inputs, in binding-form order.
        outputs: declared outputs.
        shared_names: names that cross scopes on purpose.
        layout: canvas positions of the nodes inside (the engine ignores it).
    """

    id: str
    name: str
    tree: NodeSpec
    version: int = 1
    date: str = ""
    description: str = ""
    inputs: list[SubtreePort] = field(default_factory=list)
    outputs: list[SubtreePort] = field(default_factory=list)
    shared_names: list[str] = field(default_factory=list)
    layout: dict[str, NodeLayout] = field(default_factory=dict)

    @property
    def ref(self) -> SubtreeRef:
        return SubtreeRef(self.id, self.version)

    def port(self, name: str) -> SubtreePort | None:
        """The declared input or output called ``name``, or None."""
        return next((p for p in [*self.inputs, *self.outputs] if p.name == name), None)


@dataclass
class ParameterDecl:
    """A named parameter the plan declares, with an optional initial value (X of the paper)."""

    name: str
    type: ParamType
    value: Any = None
    doc: str = ""


@dataclass
class NodeLayout:
    """Where the canvas draws a node; the engine ignores it."""

    x: float = 0.0
    y: float = 0.0
    collapsed: bool = False


@dataclass
class PlanSpec:
    """A task plan: the tree, its run policy, parameters, waypoints, objects and layout."""

    tree: NodeSpec | None = None
    name: str = ""
    description: str = ""
    run_policy: RunPolicy = RunPolicy.ONCE
    # With until_success: give up after this many identical failures in a row (the same
    # first failing node, error type and message); 0: never. Files without it read as 5.
    give_up_after: int = DEFAULT_GIVE_UP_AFTER
    # Put the cell back to its scene's seed (robot home, objects in place) before each run.
    reset_cell: bool = False
    # The simulated cell's scene the plan was taught on ("kitting_handoff"); the simulated
    # cell opens it for this plan unless told otherwise. Empty: the cell's default scene.
    scene: str = ""
    parameters: list[ParameterDecl] = field(default_factory=list)
    waypoints: list[Waypoint] = field(default_factory=list)
    objects: list[str] = field(default_factory=list)
    layout: dict[str, NodeLayout] = field(default_factory=dict)
    id: str = field(default_factory=new_id)
    # The definitions its instances run, embedded so that the plan runs without the library.
    subtrees: list[SubtreeSpec] = field(default_factory=list)

    def subtree(self, ref: SubtreeRef) -> SubtreeSpec | None:
        """The embedded definition an instance refers to (same id and version), or None."""
        return next((s for s in self.subtrees if s.id == ref.id and s.version == ref.version), None)

    def walk(self) -> Iterator[tuple[str, NodeSpec]]:
        if self.tree is not None:
            yield from self.tree.walk()

    def find(self, node_id: str) -> NodeSpec | None:
        return self.tree.find(node_id) if self.tree is not None else None

    def path_of(self, node_id: str) -> str:
        for path, node in self.walk():
            if node.id == node_id:
                return path
        return node_id
