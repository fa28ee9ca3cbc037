"""Small plans for the runtime tests, built from debug operations (they need no robot)."""

from __future__ import annotations

from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec, RunPolicy
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


def pick_behind_a_retry_plan(give_up_after: int = 2) -> PlanSpec:
    """A pick that fails 4 times behind a Retry, then a fallback that fails too, run until
    success: the root gives up after ``give_up_after`` identical failures in a row.
    """
    pick = op(
        "debug.fail",
        "grasp CUP",
        message=text("nothing between the fingers"),
        error=text("grasp_failed"),
    )
    retry = NodeSpec(
        NodeKind.RETRY, name="pick 4 times", params={"count": number(4)}, children=[pick]
    )
    ask = op("debug.fail", "ask for help", message=text("no one answered"))
    top = NodeSpec(NodeKind.SELECTOR, name="pick or ask", children=[retry, ask])
    return PlanSpec(
        tree=top, name="pick", run_policy=RunPolicy.UNTIL_SUCCESS, give_up_after=give_up_after
    )
