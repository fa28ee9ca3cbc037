"""Undo commands: every edit of a plan is one command (as in orange-canvas-core).

Each small command keeps exactly what it needs to put the plan back, so that undo restores
the saved file byte for byte. Commands change the plan only through the document's public
mutators, which also tell the views. A plan-wide field changes through a command named for
what the user does (:class:`RenamePlanCommand`, :class:`StoreWaypointsCommand`, ...).

An edit made of several changes is one :class:`CompoundCommand` whose children are small
commands built in its constructor (as orange-canvas-core's ``RemoveNodeCommand`` adds its
``RemoveLinkCommand`` children): it redoes them in order and undoes them in reverse, and the
Edit menu shows its text ("Undo Move grasp"). Views never open macros on the stack.
:mod:`instructor_app.document.subtree_commands` holds the compound edits of library subtrees.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any, ClassVar

from PySide6.QtGui import QUndoCommand

from engine.conditions import Condition
from engine.spec import Binding, NodeLayout, NodeSpec, ParameterDecl
from engine.tree import RunPolicy
from engine.types import ParamType, Waypoint
from instructor_app.document.model import PlanModel

__all__ = [
    "CompoundCommand",
    "PlanFieldCommand",
    "AddNodeCommand",
    "RemoveNodeCommand",
    "DeleteNodesCommand",
    "MoveNodeCommand",
    "ReparentCommand",
    "SetParamCommand",
    "RenameCommand",
    "SetConditionCommand",
    "SetLayoutCommand",
    "ReplaceNodeCommand",
    "RenamePlanCommand",
    "SetRunPolicyCommand",
    "SetGiveUpAfterCommand",
    "SetResetCellCommand",
    "DeclareParameterCommand",
    "StoreWaypointsCommand",
    "RemoveWaypointCommand",
    "ReplaceWaypointCommand",
]


class _Command(QUndoCommand):
    """A command on one document."""

    def __init__(self, document: PlanModel, text: str) -> None:
        super().__init__(text)
        self.document = document


class CompoundCommand(_Command):
    """One undo step made of child commands, which the constructor builds with ``add``.

    Redo runs the children in order and undo in reverse, as Qt does for the children of a
    ``QUndoCommand(text, parent)``. They are not Qt children: PySide6 leaves such a child
    owned by Python, and the parent's C++ destructor then deletes it a second time (a crash
    when the stack is cleared), so this command holds and runs its children itself.
    """

    def __init__(self, document: PlanModel, text: str) -> None:
        super().__init__(document, text)
        self.parts: list[QUndoCommand] = []

    def add(self, command: QUndoCommand) -> None:
        """Append a child command (not yet done: the stack's push runs ``redo``)."""
        self.parts.append(command)

    def redo(self) -> None:
        for command in self.parts:
            command.redo()

    def undo(self) -> None:
        for command in reversed(self.parts):
            command.undo()


# ---------------------------------------------------------------------- nodes


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
    """Delete a node with its subtree; undo puts back the subtree and its layout.

    Where the node was is read when it is taken out, so that the children of
    :class:`DeleteNodesCommand` put back siblings in their places.
    """

    def __init__(self, document: PlanModel, node_id: str) -> None:
        parent_id, index, node = document.locate(node_id)
        super().__init__(document, f"Delete {node.label}")
        self.node_id = node_id
        self.parent_id = parent_id
        self.index = index
        self.saved: NodeSpec | None = None
        self.saved_layout: dict[str, NodeLayout] = {}

    def redo(self) -> None:
        self.parent_id, self.index, _ = self.document.locate(self.node_id)
        self.saved, self.saved_layout = self.document.detach_node(self.node_id)

    def undo(self) -> None:
        assert self.saved is not None
        self.document.insert_node(self.saved, self.parent_id, self.index, self.saved_layout)


class DeleteNodesCommand(CompoundCommand):
    """Delete several nodes (none inside another) with their subtrees: one undo step."""

    def __init__(self, document: PlanModel, node_ids: Sequence[str]) -> None:
        label = document.node(node_ids[0]).label if len(node_ids) == 1 else ""
        super().__init__(document, f"Delete {label}" if label else "Delete nodes")
        for node_id in node_ids:
            self.add(RemoveNodeCommand(document, node_id))


class MoveNodeCommand(_Command):
    """Reparent or reorder a node (its subtree moves with it)."""

    def __init__(
        self,
        document: PlanModel,
        node_id: str,
        parent_id: str,
        index: int,
    ) -> None:
        old_parent, old_index, node = document.locate(node_id)
        super().__init__(document, f"Move {node.label}")
        self.node_id = node_id
        self.old = (old_parent, old_index)
        self.new = (parent_id, index)

    def redo(self) -> None:
        self.document.relocate_node(self.node_id, *self.new)

    def undo(self) -> None:
        self.document.relocate_node(self.node_id, *self.old)


class ReparentCommand(CompoundCommand):
    """Move a node (a drag onto a node, a new link) and change layout entries with it.

    Args:
        document: the document edited.
        node_id: the node moved.
        parent_id: its new parent.
        index: its place there, counted once it is taken out; None: it does not move.
        layouts: the layout entries that change in the same step (the dragged node gives
            up its hand-placed position); None or empty: none.
    """

    def __init__(
        self,
        document: PlanModel,
        node_id: str,
        parent_id: str,
        index: int | None,
        layouts: dict[str, NodeLayout | None] | None = None,
    ) -> None:
        super().__init__(document, f"Move {document.node(node_id).label}")
        if index is not None:
            self.add(MoveNodeCommand(document, node_id, parent_id, index))
        if layouts:
            self.add(SetLayoutCommand(document, layouts, "Place automatically"))


class SetParamCommand(_Command):
    """Bind an operation port to a fixed value or a reference, or unbind it (None)."""

    def __init__(
        self,
        document: PlanModel,
        node_id: str,
        port: str,
        binding: Binding | None,
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


class SetConditionCommand(_Command):
    """Set a node's pre- or post-condition (a script; "" removes it)."""

    def __init__(
        self, document: PlanModel, node_id: str, condition: Condition, script: str
    ) -> None:
        node = document.node(node_id)
        what = condition.value.replace("_", " ")
        super().__init__(document, f"Set the {what} condition of {node.label}")
        self.node_id = node_id
        self.condition = condition
        self.new = script
        self.old = node.conditions.get(condition, "")

    def redo(self) -> None:
        self.document.apply_condition(self.node_id, self.condition, self.new)

    def undo(self) -> None:
        self.document.apply_condition(self.node_id, self.condition, self.old)


class RenameCommand(_Command):
    """Give a node a name (the canvas title, the inspector's name field)."""

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
        self,
        document: PlanModel,
        layouts: dict[str, NodeLayout | None],
        text: str,
    ) -> None:
        super().__init__(document, text)
        self.new = {k: copy.copy(v) for k, v in layouts.items()}
        self.old = {k: copy.copy(document.plan.layout.get(k)) for k in layouts}

    def redo(self) -> None:
        self.document.apply_layout(self.new)

    def undo(self) -> None:
        self.document.apply_layout(self.old)


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


# ---------------------------------------------------------------------- plan-wide fields


class PlanFieldCommand(_Command):
    """Set the plan-wide field ``FIELD`` to a value; subclasses are named for the user's edit.

    The undo text is "Change the plan's <field>" (``WHAT``, else the field's name).
    """

    FIELD: ClassVar[str]
    WHAT: ClassVar[str] = ""

    def __init__(self, document: PlanModel, value: Any) -> None:
        what = self.WHAT or self.FIELD.replace("_", " ")
        super().__init__(document, f"Change the plan's {what}")
        self.new = copy.deepcopy(value)
        self.old = copy.deepcopy(getattr(document.plan, self.FIELD))

    def redo(self) -> None:
        self.document.apply_plan_field(self.FIELD, copy.deepcopy(self.new))

    def undo(self) -> None:
        self.document.apply_plan_field(self.FIELD, copy.deepcopy(self.old))


class RenamePlanCommand(PlanFieldCommand):
    """Give the plan a new name (``RenamePlanCommand(document, name)``)."""

    FIELD = "name"


class SetRunPolicyCommand(PlanFieldCommand):
    """Choose how the plan runs: once, until success, forever."""

    FIELD = "run_policy"

    def __init__(self, document: PlanModel, policy: RunPolicy) -> None:
        super().__init__(document, policy)


class SetGiveUpAfterCommand(PlanFieldCommand):
    """Choose after how many identical failures in a row a plan that runs until success
    gives up (0: never).
    """

    FIELD = "give_up_after"
    WHAT = "limit of identical failures"

    def __init__(self, document: PlanModel, limit: int) -> None:
        super().__init__(document, limit)


class SetResetCellCommand(PlanFieldCommand):
    """Choose whether the cell goes back to its scene's start before each run."""

    FIELD = "reset_cell"

    def __init__(self, document: PlanModel, reset: bool) -> None:
        super().__init__(document, reset)


class DeclareParameterCommand(PlanFieldCommand):
    """Declare a plan parameter, in place of the one of the same name if there is one."""

    FIELD = "parameters"

    def __init__(self, document: PlanModel, decl: ParameterDecl) -> None:
        params = list(document.plan.parameters)
        names = [p.name for p in params]
        if decl.name in names:
            params[names.index(decl.name)] = decl
        else:
            params.append(decl)
        super().__init__(document, params)


class StoreWaypointsCommand(PlanFieldCommand):
    """Put waypoints in the plan (recorded, imported, taught): each replaces the one of its
    name in place, the others are appended.
    """

    FIELD = "waypoints"

    def __init__(
        self,
        document: PlanModel,
        waypoints: Sequence[Waypoint],
    ) -> None:
        by_name = {w.name: w for w in waypoints}
        merged = [by_name.pop(w.name, w) for w in document.plan.waypoints]
        super().__init__(document, [*merged, *by_name.values()])


class RemoveWaypointCommand(PlanFieldCommand):
    """Take a waypoint out of the plan's list."""

    FIELD = "waypoints"

    def __init__(self, document: PlanModel, name: str) -> None:
        super().__init__(document, [w for w in document.plan.waypoints if w.name != name])


class _RenameWaypointCommand(PlanFieldCommand):
    """Put ``new`` in place of the waypoint ``old_name`` (appended when there is none)."""

    FIELD = "waypoints"

    def __init__(self, document: PlanModel, old_name: str, new: Waypoint) -> None:
        waypoints = list(document.plan.waypoints)
        names = [w.name for w in waypoints]
        if old_name in names:
            waypoints[names.index(old_name)] = new
        else:
            waypoints.append(new)
        super().__init__(document, waypoints)


class ReplaceWaypointCommand(CompoundCommand):
    """Change or teach a waypoint: the plan's list and every fixed binding holding it.

    Args:
        document: the document edited.
        old_name: the waypoint replaced (appended when the plan has none of that name).
        new: the waypoint put in its place.
        text: the undo text ("" for "Change the waypoint 'name'").
        bind: a port (node id, port) bound to ``new`` in the same step.
    """

    def __init__(
        self,
        document: PlanModel,
        old_name: str,
        new: Waypoint,
        text: str = "",
        bind: tuple[str, str] | None = None,
    ) -> None:
        super().__init__(document, text or f"Change the waypoint {old_name!r}")
        self.add(_RenameWaypointCommand(document, old_name, new))
        bound = [
            (node.id, port, binding.type or ParamType.WAYPOINT)
            for _, node in document.plan.walk()
            for port, binding in node.params.items()
            if not binding.is_ref
            and isinstance(binding.value, Waypoint)
            and binding.value.name == old_name
            and (node.id, port) != bind
        ]
        if bind is not None:
            bound.append((bind[0], bind[1], ParamType.WAYPOINT))
        for node_id, port, kind in bound:
            binding = Binding.fixed(new, kind)
            self.add(SetParamCommand(document, node_id, port, binding))
