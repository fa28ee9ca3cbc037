"""Plain edits of a PlanSpec's tree, shared by the undo commands (no Qt here)."""

from __future__ import annotations

import copy
import uuid
from collections.abc import Iterator

from engine.spec import Category, NodeLayout, NodeSpec, PlanSpec
from instructor_app.errors import InstructorError

__all__ = [
    "TreeEditError",
    "locate",
    "insert",
    "detach",
    "subtree_ids",
    "fresh_copy",
    "can_have_child",
]


class TreeEditError(InstructorError):
    """An edit that the tree cannot take (a decorator with two children, a loop)."""


def locate(plan: PlanSpec, node_id: str) -> tuple[NodeSpec | None, int, NodeSpec]:
    """(parent or None for the root, index in the parent, node); raises TreeEditError."""
    if plan.tree is None:
        raise TreeEditError(f"the plan has no node {node_id}")
    if plan.tree.id == node_id:
        return None, 0, plan.tree
    stack = [plan.tree]
    while stack:
        parent = stack.pop()
        for index, child in enumerate(parent.children):
            if child.id == node_id:
                return parent, index, child
            stack.append(child)
    raise TreeEditError(f"the plan has no node {node_id}")


def can_have_child(node: NodeSpec, extra: int = 1) -> bool:
    """Whether ``node`` can take ``extra`` more children."""
    if node.category is Category.LEAF:
        return False
    if node.category is Category.DECORATOR:
        return len(node.children) + extra <= 1
    return True


def insert(plan: PlanSpec, parent_id: str | None, index: int, node: NodeSpec) -> None:
    """Put ``node`` (with its subtree) under ``parent_id`` at ``index``; None: as the root."""
    if parent_id is None:
        if plan.tree is not None:
            raise TreeEditError("the plan already has a root node; add the node under it")
        plan.tree = node
        return
    _, _, parent = locate(plan, parent_id)
    if not can_have_child(parent):
        what = "a leaf" if parent.category is Category.LEAF else "a decorator that has its child"
        raise TreeEditError(f"{parent.label!r} is {what} and cannot take another child")
    if not 0 <= index <= len(parent.children):
        raise TreeEditError(f"{parent.label!r} has no place {index}")
    parent.children.insert(index, node)


def detach(plan: PlanSpec, node_id: str) -> tuple[str | None, int, NodeSpec]:
    """Take a node (with its subtree) out; returns (parent id or None, index, node)."""
    parent, index, node = locate(plan, node_id)
    if parent is None:
        plan.tree = None
        return None, 0, node
    del parent.children[index]
    return parent.id, index, node


def subtree_ids(node: NodeSpec) -> Iterator[str]:
    """The ids of the node and of every node below it."""
    for _, child in node.walk():
        yield child.id


def fresh_copy(
    node: NodeSpec, layout: dict[str, NodeLayout]
) -> tuple[NodeSpec, dict[str, NodeLayout]]:
    """A deep copy with new ids (for paste and duplicate), and its layout under the new ids."""
    clone = copy.deepcopy(node)
    new_layout: dict[str, NodeLayout] = {}
    for (_, old), (_, new) in zip(node.walk(), clone.walk(), strict=True):
        new.id = uuid.uuid4().hex
        if old.id in layout:
            new_layout[new.id] = copy.copy(layout[old.id])
    return clone, new_layout
