"""PlanDocument: a PlanModel with its undo stack and its file.

Every edit a view makes goes through a method here that pushes one undo command
(:mod:`instructor_app.document.commands`; an edit of several changes is one command with
children); the commands call the model's public mutators.
"""

from __future__ import annotations

import copy
from pathlib import Path

from PySide6.QtCore import QObject
from PySide6.QtGui import QUndoCommand, QUndoStack

from engine.conditions import Condition
from engine.files import PlanFileError, load_plan, loads_plan, save_plan
from engine.spec import Binding, NodeLayout, NodeSpec, ParameterDecl, PlanSpec
from engine.subtree_ops import instance_name
from engine.tree import RunPolicy
from engine.types import Waypoint
from instructor_app.document import tree_ops
from instructor_app.document.commands import (
    AddNodeCommand,
    CompoundCommand,
    DeclareParameterCommand,
    DeleteNodesCommand,
    MoveNodeCommand,
    RemoveNodeCommand,
    RemoveWaypointCommand,
    RenameCommand,
    RenamePlanCommand,
    ReparentCommand,
    ReplaceWaypointCommand,
    SetConditionCommand,
    SetGiveUpAfterCommand,
    SetLayoutCommand,
    SetParamCommand,
    SetResetCellCommand,
    SetRunPolicyCommand,
    StoreWaypointsCommand,
)
from instructor_app.document.model import DocumentError, PlanModel
from instructor_app.document.subtree_commands import PasteWithSubtreesCommand

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

    def push(self, command: QUndoCommand) -> None:
        """Do ``command`` and put it on the undo stack (the editing methods' one way in)."""
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
        parent_id, index = self._place(parent_id, index)
        self.push(AddNodeCommand(self, node, parent_id, index, layout))
        return node.id

    def _place(self, parent_id: str | None, index: int | None) -> tuple[str | None, int]:
        """Where a new node goes: under ``parent_id`` (None: as the root) at ``index``
        (None: last); DocumentError if it cannot go there.
        """
        if parent_id is None and self.plan.tree is not None:
            raise DocumentError("the plan already has a root node; add the node under it")
        if parent_id is None:
            return None, 0
        parent = self.node(parent_id)
        if not tree_ops.can_have_child(parent):
            raise DocumentError(f"{parent.label!r} cannot take another child")
        return parent_id, len(parent.children) if index is None else index

    def remove_node(self, node_id: str) -> None:
        """Delete a node with the nodes below it."""
        self.node(node_id)
        self.push(RemoveNodeCommand(self, node_id))

    def remove_nodes(self, node_ids: list[str]) -> None:
        """Delete several nodes (none below another) with the nodes below them: one step."""
        if not node_ids:
            raise DocumentError("select a node to delete")
        for node_id in node_ids:
            self.node(node_id)
        self.push(DeleteNodesCommand(self, node_ids))

    def move_node(self, node_id: str, parent_id: str, index: int) -> None:
        """Reparent or reorder; ``index`` counts in the new parent's children as they are
        after the node was taken out.
        """
        if self._moves(node_id, parent_id, index):
            self.push(MoveNodeCommand(self, node_id, parent_id, index))

    def move_to_end(
        self,
        node_id: str,
        parent_id: str,
        layouts: dict[str, NodeLayout | None] | None = None,
    ) -> None:
        """Make a node the last child of ``parent_id`` (a drag onto a node, a new link), and
        change ``layouts`` (the node's hand-placed position) in the same undo step.
        """
        current_parent, _, _ = self.locate(node_id)
        index = len(self.node(parent_id).children) - (1 if current_parent == parent_id else 0)
        moves = self._moves(node_id, parent_id, index)
        if moves or layouts:
            self.push(ReparentCommand(self, node_id, parent_id, index if moves else None, layouts))

    def _moves(self, node_id: str, parent_id: str, index: int) -> bool:
        """Whether the node goes elsewhere; DocumentError if it cannot go there."""
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
        return not (current_parent == parent_id and current_index == index)  # else: no step

    def set_param(self, node_id: str, port: str, binding: Binding | None) -> None:
        """Bind a port; an instance still called what its first input made it ("Pick cup")
        is renamed after the new value in the same undo step.
        """
        node = self.node(node_id)
        subtree = self.plan.subtree(node.subtree) if node.subtree is not None else None
        if subtree is None or node.name != instance_name(subtree, node.params):
            self.push(SetParamCommand(self, node_id, port, binding))
            return
        params = {k: v for k, v in node.params.items() if k != port}
        named = instance_name(subtree, params if binding is None else {**params, port: binding})
        command = CompoundCommand(self, f"Set {port} of {node.label}")
        command.add(SetParamCommand(self, node_id, port, binding))
        if named != node.name:
            command.add(RenameCommand(self, node_id, named))
        self.push(command)

    def set_condition(self, node_id: str, condition: Condition, script: str) -> None:
        """Set a node's pre- or post-condition as one undo step ("" removes it); a script
        that says what is there already pushes nothing.
        """
        old = self.node(node_id).conditions.get(condition, "")
        if old.strip() == script.strip():
            return
        self.push(SetConditionCommand(self, node_id, condition, script))

    def rename(self, node_id: str, name: str) -> None:
        if self.node(node_id).name != name:
            self.push(RenameCommand(self, node_id, name))

    def set_layout(self, layouts: dict[str, NodeLayout | None], text: str = "Move nodes") -> None:
        self.push(SetLayoutCommand(self, layouts, text))

    def set_collapsed(self, node_id: str, collapsed: bool) -> None:
        layout = copy.copy(self.plan.layout.get(node_id)) or NodeLayout()
        layout.collapsed = collapsed
        self.set_layout({node_id: layout}, "Collapse" if collapsed else "Expand")

    # plan-wide fields, each a command named for the edit

    def rename_plan(self, name: str) -> None:
        """Give the plan a new name."""
        self.push(RenamePlanCommand(self, name))

    def set_run_policy(self, policy: RunPolicy) -> None:
        """Run the plan once, until success or forever."""
        self.push(SetRunPolicyCommand(self, policy))

    def set_give_up_after(self, limit: int) -> None:
        """Give up running until success after this many identical failures in a row (0:
        never).
        """
        self.push(SetGiveUpAfterCommand(self, limit))

    def set_reset_cell(self, reset: bool) -> None:
        """Put the cell back to its scene's start before each run, or not."""
        self.push(SetResetCellCommand(self, reset))

    def declare_parameter(self, decl: ParameterDecl) -> None:
        """Declare a plan parameter, replacing the one of that name if there is one."""
        self.push(DeclareParameterCommand(self, decl))

    def store_waypoints(self, waypoints: list[Waypoint]) -> None:
        """Put waypoints in the plan: same-named ones are replaced in place, others appended
        (no undo step when that changes nothing).
        """
        command = StoreWaypointsCommand(self, waypoints)
        if command.new != command.old:
            self.push(command)

    def remove_waypoint(self, name: str) -> None:
        """Take the waypoint ``name`` out of the plan's list."""
        if all(w.name != name for w in self.plan.waypoints):
            raise DocumentError(f"the plan has no waypoint {name!r}")
        self.push(RemoveWaypointCommand(self, name))

    def replace_waypoint(
        self, old_name: str, new: Waypoint, text: str = "", bind: tuple[str, str] | None = None
    ) -> None:
        """Put ``new`` in place of the plan's waypoint ``old_name`` (appended when there is
        none) and into every fixed binding that holds that waypoint, and bind it to the
        port ``bind`` = (node id, port) if given: one undo step.
        """
        names = [w.name for w in self.plan.waypoints]
        if new.name != old_name and new.name in names:
            raise DocumentError(f"there is already a waypoint {new.name!r}")
        self.push(ReplaceWaypointCommand(self, old_name, new, text, bind))

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
        # its instances' subtrees come too
        parent_id, index = self._place(parent_id, index)
        self.push(PasteWithSubtreesCommand(self, clone, parent_id, index, layout, missing))
        return clone.id

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
