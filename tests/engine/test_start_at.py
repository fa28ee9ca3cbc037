"""BehaviorTree.start_at: a run that starts at a node, the nodes before it counted as done."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, rooted, with_children

from engine.composites import Selector, Sequence
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS


def test_the_nodes_before_it_on_its_path_are_done_and_not_evaluated(ctx: Any) -> None:
    a, b, c, d = (ScriptedLeaf(ctx, name) for name in "abcd")
    x, y = ScriptedLeaf(ctx, "x", FAILURE), ScriptedLeaf(ctx, "y", RUNNING, SUCCESS)
    options = with_children(Selector(ctx, "options"), [x, y])
    inner = with_children(Sequence(ctx, "inner"), [b, options, c])
    tree = rooted(ctx, with_children(Sequence(ctx, "top"), [a, inner, d]))
    marked = tree.start_at("y")
    assert marked == {"x": FAILURE, "a": SUCCESS, "b": SUCCESS}
    assert tree.tick() is RUNNING and tree.tick() is SUCCESS
    assert (a.updates, b.updates, x.updates) == (0, 0, 0)  # done: never evaluated
    assert (y.updates, c.updates, d.updates) == (2, 1, 1)  # from y on, as usual
    tree.reset()
    assert a.status is IDLE and tree.tick() is SUCCESS and a.updates == 1  # a full run again


def test_only_a_fresh_tree_and_a_known_node(ctx: Any) -> None:
    tree = rooted(ctx, with_children(Sequence(ctx, "top"), [ScriptedLeaf(ctx, "a")]))
    with pytest.raises(KeyError):
        tree.start_at("nope")
    assert tree.start_at("top") == {}  # the first node: nothing before it
    tree.tick()
    with pytest.raises(ValueError, match="before its first tick"):
        tree.start_at("a")
