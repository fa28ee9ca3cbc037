"""Undo commands: every edit of a plan is one small command (as in orange-canvas-core).

Each command keeps exactly what it needs to put the plan back, so that undo restores the
saved file byte for byte. Commands change the plan only through the document's
public mutators, which also tell the views.
"""

from __future__ import annotations

import copy
from typing import Any

from PySide6.QtGui import QUndoCommand

from engine.spec import Binding, NodeLayout, NodeSpec
from instructor_app.document.model import PlanModel

__all__ = [
    "AddNodeCommand",
    "RemoveNodeCommand",
    "MoveNodeCommand",
    "SetParamCommand",
    "RenameCommand",
    "SetLayoutCommand",
    "SetPlanFieldCommand",
    "ReplaceNodeCommand",
]


class _Command(QUndoCommand):
    def __init__(self, document: PlanModel, text: str) -> None:
        super().__init__(text)
        self.document = document


class AddNodeCommand(_Command):
    """Insert a subtree (a new node, a paste, a duplicate) with its layout."""

    def __init__(
        self,
        document: PlanModel,
        node: NodeSpec,
        parent_id: str | None,
        index: int,
        layout: dict[str, NodeLayout] | None = None,
        text: str = "",
    ) -> None:
        super().__init__(document, text or f"Add {node.label}")
        self.node = node
        self.parent_id = parent_id
        self.index = index
        # Only the added nodes' layout: undo takes exactly these entries out again.
        ids = {n.id for _, n in node.walk()}
        self.layout = {k: v for k, v in (layout or {}).items() if k in ids}

    def redo(self) -> None:
        self.document.insert_node(copy.deepcopy(self.node), self.parent_id, self.index, self.layout)

    def undo(self) -> None:
        self.document.detach_node(self.node.id)


class RemoveNodeCommand(_Command):
    """Delete a node with its subtree; undo puts back the subtree and its layout."""

    def __init__(self, document: PlanModel, node_id: str) -> None:
        parent_id, index, node = document.locate(node_id)
        super().__init__(document, f"Delete {node.label}")
        self.node_id = node_id
        self.parent_id = parent_id
        self.index = index
        self.saved: NodeSpec | None = None
        self.saved_layout: dict[str, NodeLayout] = {}

    def redo(self) -> None:
        self.saved, self.saved_layout = self.document.detach_node(self.node_id)

    def undo(self) -> None:
        assert self.saved is not None
        self.document.insert_node(self.saved, self.parent_id, self.index, self.saved_layout)


class MoveNodeCommand(_Command):
    """Reparent or reorder a node (its subtree moves with it)."""

    def __init__(self, document: PlanModel, node_id: str, parent_id: str, index: int) -> None:
        old_parent, old_index, node = document.locate(node_id)
        super().__init__(document, f"Move {node.label}")
        self.node_id = node_id
        self.old = (old_parent, old_index)
        self.new = (parent_id, index)

    def redo(self) -> None:
        self.document.relocate_node(self.node_id, *self.new)

    def undo(self) -> None:
        self.document.relocate_node(self.node_id, *self.old)


class SetParamCommand(_Command):
    """Bind an operation port to a fixed value or a reference, or unbind it (None)."""

    def __init__(
        self, document: PlanModel, node_id: str, port: str, binding: Binding | None
    ) -> None:
        node = document.node(node_id)
        super().__init__(document, f"Set {port} of {node.label}")
        self.node_id = node_id
        self.port = port
        self.new = binding
        self.old = node.params.get(port)

    def redo(self) -> None:
        self.document.set_binding(self.node_id, self.port, self.new)

    def undo(self) -> None:
        self.document.set_binding(self.node_id, self.port, self.old)


class RenameCommand(_Command):
    def __init__(self, document: PlanModel, node_id: str, name: str) -> None:
        node = document.node(node_id)
        super().__init__(document, f"Rename {node.label}")
        self.node_id = node_id
        self.new = name
        self.old = node.name

    def redo(self) -> None:
        self.document.rename_node(self.node_id, self.new)

    def undo(self) -> None:
        self.document.rename_node(self.node_id, self.old)


class SetLayoutCommand(_Command):
    """Move nodes on the canvas or collapse/expand them (None: no stored layout)."""

    def __init__(
        self, document: PlanModel, layouts: dict[str, NodeLayout | None], text: str
    ) -> None:
        super().__init__(document, text)
        self.new = {k: copy.copy(v) for k, v in layouts.items()}
        self.old = {k: copy.copy(document.plan.layout.get(k)) for k in layouts}

    def redo(self) -> None:
        self.document.apply_layout(self.new)

    def undo(self) -> None:
        self.document.apply_layout(self.old)


class SetPlanFieldCommand(_Command):
    """Change a plan-wide field: name, description, run_policy, reset_cell, parameters,
    waypoints, objects.
    """

    FIELDS = (
        "name",
        "description",
        "run_policy",
        "reset_cell",
        "parameters",
        "waypoints",
        "objects",
        "subtrees",
    )

    def __init__(self, document: PlanModel, field: str, value: Any) -> None:
        if field not in self.FIELDS:
            raise ValueError(f"{field!r} is not a plan field")
        super().__init__(document, f"Change the plan's {field.replace('_', ' ')}")
        self.field = field
        self.new = copy.deepcopy(value)
        self.old = copy.deepcopy(getattr(document.plan, field))

    def redo(self) -> None:
        self.document.apply_plan_field(self.field, copy.deepcopy(self.new))

    def undo(self) -> None:
        self.document.apply_plan_field(self.field, copy.deepcopy(self.old))


class ReplaceNodeCommand(_Command):
    """Put another node (with its subtree) where a node is: nodes <-> a subtree instance."""

    def __init__(
        self,
        document: PlanModel,
        node_id: str,
        node: NodeSpec,
        layout: dict[str, NodeLayout] | None = None,
        text: str = "",
    ) -> None:
        _, _, old = document.locate(node_id)
        super().__init__(document, text or f"Replace {old.label}")
        self.old_id = node_id
        self.node = node
        ids = {n.id for _, n in node.walk()}
        self.layout = {k: v for k, v in (layout or {}).items() if k in ids}
        self.saved: NodeSpec | None = None
        self.saved_layout: dict[str, NodeLayout] = {}

    def redo(self) -> None:
        self.saved, self.saved_layout = self.document.replace_node(
            self.old_id, copy.deepcopy(self.node), self.layout
        )

    def undo(self) -> None:
        assert self.saved is not None
        self.document.replace_node(self.node.id, self.saved, self.saved_layout)
