"""Tidy top-down tree layout (pure Python, no Qt).

A variant of Reingold-Tilford: every subtree is laid out on its own, then its children's
subtrees are placed left to right in tick order, each pushed right only as far as needed so
that no level of it overlaps the subtrees already placed (the contours), and the parent is
centred over its first and last child. Children of collapsed nodes are not laid out.

Contours are stored deepest level first, so that putting a parent on top of its subtree is an
append; a chain of single children therefore costs O(n), not O(n^2).
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass

from engine.spec import NodeSpec

__all__ = ["LayoutMetrics", "tidy_layout", "visible_children", "descendant_count"]


@dataclass(frozen=True)
class LayoutMetrics:
    """Sizes the layout works with (scene units).

    Attributes:
        node_width: width of a node when ``width_of`` is not given.
        level_height: vertical distance between the tops of two levels.
        gap: horizontal space between neighbouring subtrees.
    """

    node_width: float = 180.0
    level_height: float = 140.0
    gap: float = 30.0


# A contour: (left, right) extent per level, relative to the subtree root's centre, deepest
# level first (index -1 is the root's own level).
_Contour = list[tuple[float, float]]


def visible_children(node: NodeSpec, collapsed: Collection[str]) -> list[NodeSpec]:
    """The children drawn below ``node``: none when it is collapsed."""
    return [] if node.id in collapsed else node.children


def descendant_count(node: NodeSpec) -> int:
    """How many nodes lie below ``node`` (the "+N" of a collapsed node)."""
    count = 0
    stack = list(node.children)
    while stack:
        current = stack.pop()
        count += 1
        stack.extend(current.children)
    return count


def tidy_layout(
    root: NodeSpec | None,
    collapsed: Collection[str] = (),
    metrics: LayoutMetrics = LayoutMetrics(),
    width_of: Callable[[NodeSpec], float] | None = None,
) -> dict[str, tuple[float, float]]:
    """Top-left positions of every visible node.

    Args:
        root: the tree (None: empty plan).
        collapsed: ids of collapsed nodes (their descendants get no position).
        metrics: spacing.
        width_of: width of a node (default: ``metrics.node_width`` for all).

    Returns:
        node id -> (x, y) of the node's top-left corner; the root's top-left is (0, 0)
        when it is the widest point, and x grows to the right, y downwards.
    """
    if root is None:
        return {}
    widths: dict[str, float] = {}
    offsets: dict[str, float] = {}  # child centre relative to its parent's centre
    contours: dict[str, _Contour] = {}
    for node in _post_order(root, collapsed):
        width = width_of(node) if width_of is not None else metrics.node_width
        widths[node.id] = width
        children = visible_children(node, collapsed)
        contours[node.id] = _place_children(node, children, width, contours, offsets, metrics)
    return _absolute(root, collapsed, widths, offsets, contours[root.id], metrics)


def _post_order(root: NodeSpec, collapsed: Collection[str]) -> list[NodeSpec]:
    """Nodes with every child before its parent (iterative: plans may be deep)."""
    order: list[NodeSpec] = []
    stack = [root]
    while stack:
        node = stack.pop()
        order.append(node)
        stack.extend(visible_children(node, collapsed))
    order.reverse()
    return order


def _place_children(
    node: NodeSpec,
    children: list[NodeSpec],
    width: float,
    contours: dict[str, _Contour],
    offsets: dict[str, float],
    metrics: LayoutMetrics,
) -> _Contour:
    """Set the children's offsets; return the node's contour (children's are consumed)."""
    own = (-width / 2.0, width / 2.0)
    if not children:
        return [own]
    acc = contours.pop(children[0].id)  # reused in place: a child's contour is needed once
    positions = [0.0]
    for child in children[1:]:
        contour = contours.pop(child.id)
        shift = max(
            acc[-1 - d][1] - contour[-1 - d][0] + metrics.gap
            for d in range(min(len(acc), len(contour)))
        )
        positions.append(shift)
        acc = _merge(acc, contour, shift)
    centre = (positions[0] + positions[-1]) / 2.0
    for child, position in zip(children, positions, strict=True):
        offsets[child.id] = position - centre
    if centre != 0.0:
        acc = [(left - centre, right - centre) for left, right in acc]
    acc.append(own)
    return acc


def _merge(acc: _Contour, contour: _Contour, shift: float) -> _Contour:
    """The union of ``acc`` and ``contour`` shifted right by ``shift``."""
    depth_acc, depth_new = len(acc), len(contour)
    if depth_new > depth_acc:
        # The new subtree is deeper: its deep levels belong to it alone.
        merged = [(left + shift, right + shift) for left, right in contour[: depth_new - depth_acc]]
        merged.extend(acc)
        acc = merged
    for d in range(depth_new):
        left, right = acc[-1 - d]
        new_left, new_right = contour[-1 - d]
        acc[-1 - d] = (min(left, new_left + shift), max(right, new_right + shift))
    return acc


def _absolute(
    root: NodeSpec,
    collapsed: Collection[str],
    widths: dict[str, float],
    offsets: dict[str, float],
    root_contour: _Contour,
    metrics: LayoutMetrics,
) -> dict[str, tuple[float, float]]:
    """Turn relative offsets into top-left corners, the tree's left edge at x = 0."""
    leftmost = min(left for left, _ in root_contour)
    positions: dict[str, tuple[float, float]] = {}
    stack: list[tuple[NodeSpec, float, int]] = [(root, -leftmost, 0)]
    while stack:
        node, centre, depth = stack.pop()
        positions[node.id] = (centre - widths[node.id] / 2.0, depth * metrics.level_height)
        for child in visible_children(node, collapsed):
            stack.append((child, centre + offsets[child.id], depth + 1))
    return positions
