"""The tidy tree layout (pure Python, no Qt)."""

from __future__ import annotations

import itertools
import random

from engine.spec import NodeKind, NodeSpec
from instructor_app.canvas.layout import LayoutMetrics, descendant_count, tidy_layout

METRICS = LayoutMetrics(node_width=100.0, level_height=80.0, gap=20.0)


def _seq(*children: NodeSpec, name: str = "") -> NodeSpec:
    return NodeSpec(NodeKind.SEQUENCE, name=name, children=list(children))


def _leaf(name: str = "") -> NodeSpec:
    return NodeSpec(NodeKind.WAIT, name=name)


def _random_tree(count: int, seed: int) -> NodeSpec:
    rnd = random.Random(seed)
    root = _seq()
    composites = [root]
    for _ in range(count - 1):
        node = _seq() if rnd.random() < 0.35 else _leaf()
        rnd.choice(composites).children.append(node)
        if node.kind is NodeKind.SEQUENCE:
            composites.append(node)
    return root


def _depths(root: NodeSpec) -> dict[str, int]:
    depths = {root.id: 0}
    for _, node in root.walk():
        for child in node.children:
            depths[child.id] = depths[node.id] + 1
    return depths


def test_empty_and_single() -> None:
    assert tidy_layout(None) == {}
    root = _leaf()
    assert tidy_layout(root, metrics=METRICS) == {root.id: (0.0, 0.0)}


def test_children_in_tick_order_left_to_right_and_one_level_down() -> None:
    a, b, c = _leaf("a"), _leaf("b"), _leaf("c")
    root = _seq(a, b, c)
    pos = tidy_layout(root, metrics=METRICS)
    assert pos[a.id][0] < pos[b.id][0] < pos[c.id][0]
    assert {pos[n.id][1] for n in (a, b, c)} == {80.0}
    assert pos[b.id][0] - pos[a.id][0] == 120.0  # width + gap


def test_parent_centred_over_first_and_last_child() -> None:
    tree = _random_tree(120, seed=3)
    pos = tidy_layout(tree, metrics=METRICS)
    for _, node in tree.walk():
        if node.children:
            first, last = pos[node.children[0].id][0], pos[node.children[-1].id][0]
            assert abs(pos[node.id][0] - (first + last) / 2.0) < 1e-9


def test_no_two_nodes_overlap_and_order_holds_on_every_level() -> None:
    for seed in range(5):
        tree = _random_tree(300, seed)
        pos = tidy_layout(tree, metrics=METRICS)
        depths = _depths(tree)
        levels: dict[int, list[float]] = {}
        for node_id, (x, y) in pos.items():
            assert y == depths[node_id] * 80.0
            levels.setdefault(depths[node_id], []).append(x)
        for xs in levels.values():
            xs.sort()
            assert all(b - a >= 100.0 + 20.0 - 1e-9 for a, b in itertools.pairwise(xs))
        # Depth-first tick order is left-to-right order within each level.
        seen: dict[int, float] = {}
        for _, node in tree.walk():
            depth = depths[node.id]
            assert pos[node.id][0] > seen.get(depth, float("-inf"))
            seen[depth] = pos[node.id][0]


def test_collapsed_subtree_is_hidden_and_takes_no_room() -> None:
    inner = _seq(_leaf(), _leaf(), _leaf(), _leaf())
    other_child = _leaf()
    other = _seq(other_child)
    root = _seq(inner, other)
    open_pos = tidy_layout(root, metrics=METRICS)
    closed = tidy_layout(root, collapsed={inner.id}, metrics=METRICS)
    assert set(closed) == {root.id, inner.id, other.id, other_child.id}
    assert closed[other.id][0] - closed[inner.id][0] == 120.0
    assert open_pos[other.id][0] - open_pos[inner.id][0] > 120.0
    assert descendant_count(inner) == 4


def test_left_edge_at_zero_and_deep_chain_is_fast() -> None:
    node = _leaf()
    for _ in range(3000):  # deeper than Python's recursion limit
        node = _seq(node)
    pos = tidy_layout(node, metrics=METRICS)
    assert len(pos) == 3001
    assert min(x for x, _ in pos.values()) == 0.0


def test_variable_widths() -> None:
    wide, narrow = _leaf("wide"), _leaf("narrow")
    root = _seq(wide, narrow)
    pos = tidy_layout(root, metrics=METRICS, width_of=lambda n: 300.0 if n is wide else 50.0)
    assert pos[narrow.id][0] - pos[wide.id][0] == 300.0 + 20.0
