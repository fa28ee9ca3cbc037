"""Helpers of the robot capability tests: build small plans, run them on a SimCellSession."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

from capabilities.base import Capability, CapabilityRegistry
from capabilities.freedrive import capability as freedrive
from capabilities.gripper import capability as gripper
from capabilities.motion import capability as motion
from capabilities.sim.session import SimCellSession
from capabilities.timing import capability as timing
from capabilities.tool import capability as tool
from engine.build import build_tree
from engine.executor import run_to_end
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.tree import BehaviorTree
from engine.types import type_of_value
from engine.validation import validate_plan

__all__ = [
    "DOWN",
    "Run",
    "op",
    "registry_for",
    "run_plan",
    "seq",
]

DOWN = (1.0, 0.0, 0.0, 0.0)  # tool z axis pointing at the table


def all_capabilities() -> list[Capability]:
    return [motion(), gripper(), tool(), freedrive(), timing()]


def registry_for(
    session: Any, settings: dict[str, dict[str, Any]] | None = None
) -> CapabilityRegistry:
    return CapabilityRegistry(all_capabilities(), cell=session, settings=settings)


def op(op_id: str, label: str = "", /, **params: Any) -> NodeSpec:
    """An operation node; a str value starting with '$' is a reference, others fixed
    (with the type of the value; pass a Binding for another type).
    """
    bindings: dict[str, Binding] = {}
    for port, value in params.items():
        if isinstance(value, Binding):
            bindings[port] = value
        elif isinstance(value, str) and value.startswith("$"):
            bindings[port] = Binding.reference(value[1:])
        else:
            bindings[port] = Binding.fixed(value, type_of_value(value))
    return NodeSpec(NodeKind.OPERATION, name=label or op_id, op=op_id, params=bindings)


def seq(*children: NodeSpec, name: str = "") -> NodeSpec:
    return NodeSpec(NodeKind.SEQUENCE, name=name, children=list(children))


class Run:
    """A finished run: its status and the nodes' messages by name."""

    def __init__(self, tree: BehaviorTree, status: Status) -> None:
        self.tree = tree
        self.status = status

    def messages(self) -> dict[str, str]:
        return {node.name: node.message for node in self.tree.iterate() if node.message}

    def statuses(self) -> dict[str, Status]:
        return {node.name: node.status for node in self.tree.iterate()}

    def failure(self) -> str:
        return " | ".join(f"{k}: {v}" for k, v in self.messages().items())

    def value(self, key: str) -> Any:
        return self.tree.blackboard.get(key)


def build(
    session: SimCellSession, root: NodeSpec, registry: CapabilityRegistry | None = None
) -> BehaviorTree:
    registry = registry or registry_for(session)
    plan = PlanSpec(root, "test")
    errors = [p for p in validate_plan(plan, registry) if p.severity == "error"]
    assert not errors, errors
    return build_tree(plan, registry, clock=session.clock)


def run_plan(
    session: SimCellSession,
    root: NodeSpec,
    registry: CapabilityRegistry | None = None,
    timeout: float = 60.0,
) -> Run:
    """Run a plan to its end in an executor (real-time ``timeout``)."""
    tree = build(session, root, registry)
    result = run_to_end(tree, rate_hz=200.0, timeout=timeout)
    assert result.reason == "finished", result
    return Run(tree, result.status)


def sim_steps(session: SimCellSession, step: float, limit: float) -> Iterator[float]:
    """Advance simulated time by ``step`` until ``limit`` seconds; yields the clock."""
    start = session.clock()
    while session.clock() - start < limit:
        session.sim.wait_sim(step)
        yield session.clock()
