"""PlanDocument: a PlanModel with its undo stack and its file.

Every edit a view makes goes through a method here that pushes one undo command
(:mod:`instructor_app.document.commands`); the commands call the model's public mutators.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject
from PySide6.QtGui import QUndoStack

from engine.files import PlanFileError, load_plan, loads_plan, save_plan
from engine.spec import Binding, NodeLayout, NodeSpec, PlanSpec
from engine.types import ParamType, Waypoint
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
from instructor_app.document.model import DocumentError, PlanModel

__all__ = ["PlanDocument"]


class PlanDocument(PlanModel):
    """One open plan with undo and a file: what the Instructor's views edit."""

    def __init__(
        self, parent: QObject | None = None, aliases: dict[str, str] | None = None
    ) -> None:
        super().__init__(parent, aliases)
        self.undo_stack = QUndoStack(self)
        self.undo_stack.cleanChanged.connect(self._on_clean_changed)

    def _on_clean_changed(self, clean: bool) -> None:
        self.dirty_changed.emit(not clean)

    @property
    def dirty(self) -> bool:
        return not self.undo_stack.isClean()

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
        after the node was taken out.
        """
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

    def replace_waypoint(
        self, old_name: str, new: Waypoint, text: str = "", bind: tuple[str, str] | None = None
    ) -> None:
        """Put ``new`` in place of the plan's waypoint ``old_name`` (appended when there is
        none) and into every fixed binding that holds that waypoint, and bind it to the
        port ``bind`` = (node id, port) if given: one undo step.
        """
        waypoints = list(self.plan.waypoints)
        names = [w.name for w in waypoints]
        if new.name != old_name and new.name in names:
            raise DocumentError(f"there is already a waypoint {new.name!r}")
        if old_name in names:
            waypoints[names.index(old_name)] = new
        else:
            waypoints.append(new)
        bound = [
            (node.id, port, binding)
            for _, node in self.plan.walk()
            for port, binding in node.params.items()
            if not binding.is_ref
            and isinstance(binding.value, Waypoint)
            and binding.value.name == old_name
            and (node.id, port) != bind
        ]
        if bind is not None:
            bound.append((bind[0], bind[1], Binding.fixed(new, ParamType.WAYPOINT)))
        self.undo_stack.beginMacro(text or f"Change the waypoint {old_name!r}")
        try:
            self.set_plan_field("waypoints", waypoints)
            for node_id, port, binding in bound:
                self.set_param(
                    node_id, port, Binding.fixed(new, binding.type or ParamType.WAYPOINT)
                )
        finally:
            self.undo_stack.endMacro()

    def paste(self, text: str, parent_id: str | None, index: int | None = None) -> str:
        """Insert clipboard text (from :meth:`subtree_json`) with fresh ids; returns the new id."""
        try:
            fragment = loads_plan(text, "clipboard", self.aliases)
        except PlanFileError as exc:
            raise DocumentError(f"the clipboard holds no plan nodes ({exc})") from exc
        if fragment.tree is None:
            raise DocumentError("the clipboard holds no plan nodes")
        clone, layout = tree_ops.fresh_copy(fragment.tree, fragment.layout)
        missing = [s for s in fragment.subtrees if self.plan.subtree(s.ref) is None]
        if not missing:
            return self.add_node(clone, parent_id, index, layout)
        self.undo_stack.beginMacro(f"Paste {clone.label}")  # its instances' subtrees come too
        try:
            self._push(SetPlanFieldCommand(self, "subtrees", [*self.plan.subtrees, *missing]))
            return self.add_node(clone, parent_id, index, layout)
        finally:
            self.undo_stack.endMacro()

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
        self._replace_plan(PlanSpec(name="Untitled plan"), None)

    def open(self, path: str | Path) -> None:
        """Load a plan; on error raise DocumentError and leave the document as it was."""
        try:
            plan = load_plan(path, self.aliases)
        except PlanFileError as exc:
            raise DocumentError(str(exc)) from exc
        self._replace_plan(plan, Path(path))

    def load_text(self, text: str, path: str | Path | None, source: str = "recovery") -> None:
        """Replace the plan with a serialized one (recovery); marks the document dirty."""
        try:
            plan = loads_plan(text, source, self.aliases)
        except PlanFileError as exc:
            raise DocumentError(str(exc)) from exc
        self._replace_plan(plan, Path(path) if path else None)
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

    def _replace_plan(self, plan: PlanSpec, path: Path | None) -> None:
        self.undo_stack.clear()
        self.plan = plan
        self.path = path
        self.plan_reset.emit()
        self.path_changed.emit(str(path) if path else "")
        self.plan_changed.emit()
        self.dirty_changed.emit(False)
