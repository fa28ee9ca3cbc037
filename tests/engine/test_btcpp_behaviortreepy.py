"""Our XML ticked by BehaviorTree.CPP itself (PyPI ``behaviortreepy``, which binds
BehaviorTree.CPP 4.8.2): each logic node mapped to a built-in gives the outcome our engine
gives for the same plan. behaviortreepy registers nodes without ports, so the leaves here are
the port-less ``debug.succeed`` and ``debug.fail``; Iterator and Enforce (no built-in twin)
and port checks are tested with BehaviorTree.CPP 4.10 in test_btcpp_real.py.
"""

from __future__ import annotations

from typing import Any

import pytest

from engine.btcpp import export_xml
from engine.build import build_tree
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, SUCCESS, Status
from engine.types import ParamType

bt = pytest.importorskip("behaviortreepy", reason="behaviortreepy (a dev dependency) is missing")

_N, _D, _T = ParamType.NUMBER, ParamType.DURATION, ParamType.TEXT


def ok() -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, op="debug.succeed")


def bad() -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, op="debug.fail")


def node(kind: NodeKind, *children: NodeSpec, **settings: Any) -> NodeSpec:
    params = {}
    for name, value in settings.items():
        ptype = _T if isinstance(value, str) else _D if name == "seconds" else _N
        params[name] = Binding.fixed(value, ptype)
    return NodeSpec(kind, params=params, children=list(children))


CASES = {
    "sequence fails at a failure": node(NodeKind.SEQUENCE, ok(), bad(), ok()),
    "selector falls back": node(NodeKind.SELECTOR, bad(), ok()),
    "parallel 2 of 3": node(NodeKind.PARALLEL, ok(), bad(), ok(), success=2.0, failure=2.0),
    "parallel all, any failure": node(NodeKind.PARALLEL, ok(), bad(), success="all"),
    "parallel any success": node(NodeKind.PARALLEL, bad(), ok(), success="any", failure=2.0),
    "parallel all succeed": node(NodeKind.PARALLEL, ok(), ok()),
    "inverter": node(NodeKind.INVERTER, bad()),
    "repeat 3": node(NodeKind.REPEAT, ok(), count=3.0),
    "repeat a failure": node(NodeKind.REPEAT, bad(), count=2.0),
    "retry gives up": node(NodeKind.RETRY, bad(), count=3.0),
    "retry succeeds": node(NodeKind.RETRY, ok(), count=2.0),
    "force success": node(NodeKind.FORCE_SUCCESS, bad()),
    "force failure": node(NodeKind.FORCE_FAILURE, ok()),
    "reactive sequence": node(NodeKind.REACTIVE_SEQUENCE, ok(), bad()),
    "reactive selector": node(NodeKind.REACTIVE_SELECTOR, bad(), ok()),
    "timeout over a wait": node(NodeKind.TIMEOUT, node(NodeKind.WAIT, seconds=0.01), seconds=5.0),
    "wait then fail": node(NodeKind.SEQUENCE, node(NodeKind.WAIT, seconds=0.02), bad()),
}


def _btcpp_outcome(xml: str) -> Status:
    factory = bt.BehaviorTreeFactory()
    factory.register_simple_action("debug__succeed", lambda _node: bt.NodeStatus.SUCCESS)
    factory.register_simple_action("debug__fail", lambda _node: bt.NodeStatus.FAILURE)
    result = factory.create_tree_from_text(xml).tick_while_running()
    return {bt.NodeStatus.SUCCESS: SUCCESS, bt.NodeStatus.FAILURE: FAILURE}[result]


@pytest.mark.parametrize("name", list(CASES))
def test_btcpp_ticks_our_export_to_the_outcome_our_engine_gives(name: str, registry: Any) -> None:
    plan = PlanSpec(tree=CASES[name], name=name)
    ours = build_tree(plan, registry).tick_until_done()
    assert ours in (SUCCESS, FAILURE)
    assert _btcpp_outcome(export_xml(plan, {})) is ours


def test_both_outcomes_occur() -> None:
    """The cases are not all of one outcome (a mapping that always succeeded would pass)."""
    names = {"sequence fails at a failure", "selector falls back"}
    outcomes = {name: _btcpp_outcome(export_xml(PlanSpec(tree=CASES[name]), {})) for name in names}
    assert set(outcomes.values()) == {SUCCESS, FAILURE}
