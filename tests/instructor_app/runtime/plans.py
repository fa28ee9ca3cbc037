"""Small plans for the runtime tests, built from debug operations (they need no robot)."""

from __future__ import annotations

from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType


def op(op_id: str, name: str = "", **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, name=name, op=op_id, params=dict(params))


def text(value: str) -> Binding:
    return Binding.fixed(value, ParamType.TEXT)


def number(value: float) -> Binding:
    return Binding.fixed(float(value), ParamType.NUMBER)


def failing_plan() -> PlanSpec:
    """A sequence whose second leaf fails with "no cup"."""
    first = op("debug.succeed", "first")
    broken = op("debug.fail", "look for cup", message=text("no cup"))
    inner = NodeSpec(NodeKind.SEQUENCE, name="inner", children=[broken])
    top = NodeSpec(NodeKind.SEQUENCE, name="top", children=[first, inner, op("debug.succeed")])
    return PlanSpec(tree=top, name="failing")


def endless_plan() -> PlanSpec:
    """A leaf that stays RUNNING (a million ticks) under a sequence."""
    slow = op("debug.running", "slow", ticks=number(1e6))
    return PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=[slow]), name="endless")


def invalid_plan() -> PlanSpec:
    """An operation that does not exist and a required parameter left unbound."""
    unknown = op("debug.no_such_thing", "ghost")
    unbound = op("debug.log", "say nothing")
    top = NodeSpec(NodeKind.SEQUENCE, name="top", children=[unknown, unbound])
    return PlanSpec(tree=top, name="invalid")
