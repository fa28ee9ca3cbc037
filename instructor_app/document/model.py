"""PlanDocument: the plan being edited, its undo stack and its file.

The document is the truth; the canvas and the panels are views that listen to its signals
and edit it only through its methods, each of which pushes one undo command. Signals are
fine-grained (a node inserted, removed, moved, changed) so that a view of a 1000-node plan
updates only what changed; ``plan_reset`` says everything changed (new, open).
"""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoStack

from engine.files import PlanFileError, dump_plan, load_plan, loads_plan, save_plan
from engine.spec import Binding, NodeLayout, NodeSpec, PlanSpec
from instructor_app.document import tree_ops
from instructor_app.document.commands import (
    AddNodeCommand,
    MoveNodeCommand,
    RemoveNodeCommand,
    RenameCommand,
    SetLayoutCommand,
    SetParamCommand,
    SetPlanFieldCommand,
)

__all__ = ["DocumentError", "PlanDocument", "SUBTREE_MIME"]

SUBTREE_MIME = "application/x-costar-subtree+json"
SUBTREE_FORMAT = "costar-subtree"


class DocumentError(Exception):
    """An edit or file operation that could not be done; the message says why."""


class PlanDocument(QObject):
    """One open plan.

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
        self.undo_stack = QUndoStack(self)
        self.undo_stack.cleanChanged.connect(self._on_clean_changed)

    def _on_clean_changed(self, clean: bool) -> None:
        self.dirty_changed.emit(not clean)

    # ------------------------------------------------------------------ reading

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

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

    # ------------------------------------------------------------------ editing (undoable)

    def _push(self, command: Any) -> None:
        try:
            self.undo_stack.push(command)
        except tree_ops.TreeEditError as exc:
            raise DocumentError(str(exc)) from exc

    def add_node(
        self,
        node: NodeSpec,
        parent_id: str | None = None,
        index: int | None = None,
        layout: dict[str, NodeLayout] | None = None,
    ) -> str:
        """Add a node (or subtree) under ``parent_id`` (None: as the root); returns its id."""
        if parent_id is None and self.plan.tree is not None:
            raise DocumentError("the plan already has a root node; add the node under it")
        if parent_id is not None:
            parent = self.node(parent_id)
            if not tree_ops.can_have_child(parent):
                raise DocumentError(f"{parent.label!r} cannot take another child")
            index = len(parent.children) if index is None else index
        self._push(AddNodeCommand(self, node, parent_id, index or 0, layout))
        return node.id

    def remove_node(self, node_id: str) -> None:
        self.node(node_id)
        self._push(RemoveNodeCommand(self, node_id))

    def move_node(self, node_id: str, parent_id: str, index: int) -> None:
        """Reparent or reorder; ``index`` counts in the new parent's children as they are
        after the node was taken out."""
        node = self.node(node_id)
        target = self.node(parent_id)
        if parent_id in tree_ops.subtree_ids(node):
            raise DocumentError(f"{node.label!r} cannot go inside itself")
        current_parent, current_index, _ = self.locate(node_id)
        extra = 0 if current_parent == parent_id else 1
        if not tree_ops.can_have_child(target, extra):
            raise DocumentError(f"{target.label!r} cannot take another child")
        places = len(target.children) + extra  # places once the node is taken out, plus one
        if not 0 <= index < places:
            raise DocumentError(f"{target.label!r} has no place {index} (0 to {places - 1})")
        if current_parent == parent_id and current_index == index:
            return  # nothing moves: no undo step
        self._push(MoveNodeCommand(self, node_id, parent_id, index))

    def set_param(self, node_id: str, port: str, binding: Binding | None) -> None:
        self._push(SetParamCommand(self, node_id, port, binding))

    def rename(self, node_id: str, name: str) -> None:
        if self.node(node_id).name != name:
            self._push(RenameCommand(self, node_id, name))

    def set_layout(self, layouts: dict[str, NodeLayout | None], text: str = "Move nodes") -> None:
        self._push(SetLayoutCommand(self, layouts, text))

    def set_collapsed(self, node_id: str, collapsed: bool) -> None:
        layout = copy.copy(self.plan.layout.get(node_id)) or NodeLayout()
        layout.collapsed = collapsed
        self.set_layout({node_id: layout}, "Collapse" if collapsed else "Expand")

    def set_plan_field(self, field: str, value: Any) -> None:
        self._push(SetPlanFieldCommand(self, field, value))

    # ------------------------------------------------------------------ clipboard

    def subtree_json(self, node_id: str) -> str:
        """A node with its subtree and layout as clipboard text."""
        node = self.node(node_id)
        ids = set(tree_ops.subtree_ids(node))
        fragment = PlanSpec(
            tree=node, name=SUBTREE_FORMAT,
            layout={k: v for k, v in self.plan.layout.items() if k in ids},
        )  # fmt: skip
        return dump_plan(fragment)

    def paste(self, text: str, parent_id: str | None, index: int | None = None) -> str:
        """Insert clipboard text (from :meth:`subtree_json`) with fresh ids; returns the new id."""
        try:
            fragment = loads_plan(text, "clipboard", self.aliases)
        except PlanFileError as exc:
            raise DocumentError(f"the clipboard holds no plan nodes ({exc})") from exc
        if fragment.tree is None:
            raise DocumentError("the clipboard holds no plan nodes")
        clone, layout = tree_ops.fresh_copy(fragment.tree, fragment.layout)
        return self.add_node(clone, parent_id, index, layout)

    def duplicate(self, node_id: str) -> str:
        """A copy of the node placed right after it."""
        parent_id, index, node = self.locate(node_id)
        if parent_id is None:
            raise DocumentError("the root node cannot be duplicated: it has no parent")
        clone, layout = tree_ops.fresh_copy(node, self.plan.layout)
        return self.add_node(clone, parent_id, index + 1, layout)

    def cut(self, node_id: str) -> str:
        text = self.subtree_json(node_id)
        self.remove_node(node_id)
        return text

    # ------------------------------------------------------------------ files

    def new(self) -> None:
        self._replace(PlanSpec(name="Untitled plan"), None)

    def open(self, path: str | Path) -> None:
        """Load a plan; on error raise DocumentError and leave the document as it was."""
        try:
            plan = load_plan(path, self.aliases)
        except PlanFileError as exc:
            raise DocumentError(str(exc)) from exc
        self._replace(plan, Path(path))

    def load_text(self, text: str, path: str | Path | None, source: str = "recovery") -> None:
        """Replace the plan with a serialized one (recovery); marks the document dirty."""
        try:
            plan = loads_plan(text, source, self.aliases)
        except PlanFileError as exc:
            raise DocumentError(str(exc)) from exc
        self._replace(plan, Path(path) if path else None)
        # A recovered plan is not what is on disk: no state of the stack is clean until saved.
        self.undo_stack.resetClean()

    def save(self, path: str | Path | None = None) -> Path:
        """Save (atomically) to ``path`` or the current file; returns the path."""
        target = Path(path) if path is not None else self.path
        if target is None:
            raise DocumentError("the plan has no file yet: choose where to save it")
        try:
            save_plan(self.plan, target)
        except (OSError, PlanFileError) as exc:
            raise DocumentError(f"could not save {target}: {exc}") from exc
        if target != self.path:
            self.path = target
            self.path_changed.emit(str(target))
        self.undo_stack.setClean()
        return target

    def _replace(self, plan: PlanSpec, path: Path | None) -> None:
        self.plan = plan
        self.undo_stack.clear()
        self.path = path
        self.plan_reset.emit()
        self.path_changed.emit(str(path) if path else "")
        self.plan_changed.emit()
        self.dirty_changed.emit(False)

    # ------------------------------------------------------------------ primitives (commands only)

    def _apply_insert(
        self, node: NodeSpec, parent_id: str | None, index: int, layout: dict[str, NodeLayout]
    ) -> None:
        tree_ops.insert(self.plan, parent_id, index, node)
        for key, value in layout.items():
            self.plan.layout[key] = copy.copy(value)
        self.node_inserted.emit(parent_id or "", index, node.id)
        self.plan_changed.emit()

    def _apply_detach(self, node_id: str) -> tuple[NodeSpec, dict[str, NodeLayout]]:
        parent_id, index, node = tree_ops.detach(self.plan, node_id)
        ids = list(tree_ops.subtree_ids(node))
        layout = {k: self.plan.layout.pop(k) for k in ids if k in self.plan.layout}
        self.node_removed.emit(parent_id or "", index, ids)
        self.plan_changed.emit()
        return node, layout

    def _apply_move(self, node_id: str, parent_id: str | None, index: int) -> None:
        old_parent, old_index, node = tree_ops.detach(self.plan, node_id)
        tree_ops.insert(self.plan, parent_id, index, node)
        self.node_moved.emit(node_id, old_parent or "", old_index, parent_id or "", index)
        self.plan_changed.emit()

    def _apply_param(self, node_id: str, port: str, binding: Binding | None) -> None:
        node = self.node(node_id)
        if binding is None:
            node.params.pop(port, None)
        else:
            node.params[port] = binding
        self.node_changed.emit(node_id)
        self.plan_changed.emit()

    def _apply_rename(self, node_id: str, name: str) -> None:
        self.node(node_id).name = name
        self.node_changed.emit(node_id)
        self.plan_changed.emit()

    def _apply_layout(self, layouts: dict[str, NodeLayout | None]) -> None:
        for key, value in layouts.items():
            if value is None:
                self.plan.layout.pop(key, None)
            else:
                self.plan.layout[key] = copy.copy(value)
        self.layout_changed.emit(list(layouts))
        self.plan_changed.emit()

    def _apply_plan_field(self, field: str, value: Any) -> None:
        setattr(self.plan, field, value)
        self.plan_changed.emit()


def subtree_clipboard_text(text: str) -> bool:
    """Whether clipboard text looks like copied plan nodes."""
    try:
        data = json.loads(text)
    except ValueError:
        return False
    return isinstance(data, dict) and data.get("name") == SUBTREE_FORMAT
