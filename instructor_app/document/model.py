"""PlanModel: the plan being edited, its public mutators and the signals they emit.

The model knows nothing of undo: :mod:`instructor_app.document.commands` call its mutators,
and :class:`instructor_app.document.editing.PlanDocument` pushes those commands. Signals are
fine-grained (a node inserted, removed, moved, changed) so that a view of a 1000-node plan
updates only what changed; ``plan_reset`` says everything changed (new, open).
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, Signal

from engine.conditions import Condition
from engine.files import dump_plan
from engine.spec import Binding, NodeLayout, NodeSpec, PlanSpec
from engine.subtree_ops import subtrees_in_use
from instructor_app.document import tree_ops
from instructor_app.errors import InstructorError

__all__ = ["DocumentError", "PlanModel", "SUBTREE_MIME", "SUBTREE_FORMAT"]

SUBTREE_MIME = "application/x-costar-subtree+json"
SUBTREE_FORMAT = "costar-subtree"


class DocumentError(InstructorError):
    """An edit or file operation that could not be done; the message says why."""


class PlanModel(QObject):
    """One open plan: the spec, its file path, and the mutators that change it.

    Signals:
        plan_reset: the whole plan was replaced (new, open, recovery).
        node_inserted(parent_id, index, node_id): a subtree was added ("" parent: the root).
        node_removed(parent_id, index, node_ids): a subtree was taken out (all its ids).
        node_moved(node_id, old_parent, old_index, new_parent, new_index).
        node_changed(node_id): its name, parameters or settings changed.
        layout_changed(node_ids): canvas positions or collapsed state changed.
        plan_changed: anything changed (validation and dirty marks listen here).
        path_changed(path): the file the document is saved to.
        dirty_changed(bool): unsaved changes appeared or went.
    """

    plan_reset = Signal()
    node_inserted = Signal(str, int, str)
    node_removed = Signal(str, int, list)
    node_moved: Signal = Signal(str, str, int, str, int)
    node_changed = Signal(str)
    layout_changed = Signal(list)
    plan_changed = Signal()
    path_changed = Signal(str)
    dirty_changed = Signal(bool)

    def __init__(
        self, parent: QObject | None = None, aliases: dict[str, str] | None = None
    ) -> None:
        super().__init__(parent)
        self.plan = PlanSpec(name="Untitled plan")
        self.path: Path | None = None
        self.aliases = dict(aliases or {})

    # ------------------------------------------------------------------ reading

    def node(self, node_id: str) -> NodeSpec:
        try:
            return tree_ops.locate(self.plan, node_id)[2]
        except tree_ops.TreeEditError as exc:
            raise DocumentError(str(exc)) from exc

    def locate(self, node_id: str) -> tuple[str | None, int, NodeSpec]:
        """(parent id or None for the root, index, node)."""
        try:
            parent, index, node = tree_ops.locate(self.plan, node_id)
        except tree_ops.TreeEditError as exc:
            raise DocumentError(str(exc)) from exc
        return (parent.id if parent is not None else None), index, node

    def serialized(self) -> str:
        """The plan as its file would hold it (undo tests compare these byte for byte)."""
        return dump_plan(self.plan)

    # ------------------------------------------------------------------ clipboard

    def subtree_json(self, node_id: str) -> str:
        """A node with its subtree and layout as clipboard text."""
        node = self.node(node_id)
        ids = set(tree_ops.subtree_ids(node))
        fragment = PlanSpec(
            tree=node,
            name=SUBTREE_FORMAT,
            layout={k: v for k, v in self.plan.layout.items() if k in ids},
            subtrees=subtrees_in_use(node, self.plan.subtrees),  # what its instances run
        )
        return dump_plan(fragment)

    # ------------------------------------------------------------------ mutators (no undo)

    def insert_node(
        self, node: NodeSpec, parent_id: str | None, index: int, layout: dict[str, NodeLayout]
    ) -> None:
        """Put ``node`` (with its subtree and ``layout``) under ``parent_id`` at ``index``."""
        tree_ops.insert(self.plan, parent_id, index, node)
        for key, value in layout.items():
            self.plan.layout[key] = copy.copy(value)
        self.node_inserted.emit(parent_id or "", index, node.id)
        self.plan_changed.emit()

    def detach_node(self, node_id: str) -> tuple[NodeSpec, dict[str, NodeLayout]]:
        """Take a subtree out; returns it and the layout of its nodes."""
        parent_id, index, node = tree_ops.detach(self.plan, node_id)
        ids = list(tree_ops.subtree_ids(node))
        layout = {k: self.plan.layout.pop(k) for k in ids if k in self.plan.layout}
        self.node_removed.emit(parent_id or "", index, ids)
        self.plan_changed.emit()
        return node, layout

    def replace_node(
        self, node_id: str, node: NodeSpec, layout: dict[str, NodeLayout]
    ) -> tuple[NodeSpec, dict[str, NodeLayout]]:
        """Put ``node`` where ``node_id`` is; returns the old node and its layout."""
        parent_id, index, _ = self.locate(node_id)
        old, old_layout = self.detach_node(node_id)
        self.insert_node(node, parent_id, index, layout)
        return old, old_layout

    def relocate_node(self, node_id: str, parent_id: str | None, index: int) -> None:
        """Move a node to ``index`` under ``parent_id`` (None: as the root)."""
        old_parent, old_index, node = tree_ops.detach(self.plan, node_id)
        tree_ops.insert(self.plan, parent_id, index, node)
        self.node_moved.emit(node_id, old_parent or "", old_index, parent_id or "", index)
        self.plan_changed.emit()

    def set_binding(self, node_id: str, port: str, binding: Binding | None) -> None:
        """Bind a port of a node (None: unbind it)."""
        node = self.node(node_id)
        if binding is None:
            node.params.pop(port, None)
        else:
            node.params[port] = binding
        self.node_changed.emit(node_id)
        self.plan_changed.emit()

    def apply_condition(self, node_id: str, condition: Condition, script: str) -> None:
        """Set a pre- or post-condition of a node ("": remove it)."""
        conditions = self.node(node_id).conditions
        if script.strip():
            conditions[condition] = script
        else:
            conditions.pop(condition, None)
        self.node_changed.emit(node_id)
        self.plan_changed.emit()

    def rename_node(self, node_id: str, name: str) -> None:
        """Give a node a new name."""
        self.node(node_id).name = name
        self.node_changed.emit(node_id)
        self.plan_changed.emit()

    def apply_layout(self, layouts: dict[str, NodeLayout | None]) -> None:
        """Set canvas positions (None: forget the node's position)."""
        for key, value in layouts.items():
            if value is None:
                self.plan.layout.pop(key, None)
            else:
                self.plan.layout[key] = copy.copy(value)
        self.layout_changed.emit(list(layouts))
        self.plan_changed.emit()

    def apply_plan_field(self, field: str, value: Any) -> None:
        """Set a field of the plan (name, description, run_policy, parameters, ...)."""
        setattr(self.plan, field, value)
        self.plan_changed.emit()
