"""Undo commands of edits that involve library subtrees, each one compound command.

An instance and the definition it runs travel together: the plan embeds every definition its
instances run (``PlanSpec.subtrees``). Each edit here is a
:class:`~instructor_app.document.commands.CompoundCommand` whose children change the tree
(:class:`~instructor_app.document.commands.AddNodeCommand`,
:class:`~instructor_app.document.commands.ReplaceNodeCommand`) and the embedded definitions
(:class:`EmbedSubtreesCommand`, :class:`DropUnusedSubtreesCommand`), so that undo restores
the plan byte for byte.
"""

from __future__ import annotations

from engine.spec import NodeLayout, NodeSpec, SubtreeSpec
from engine.subtree_ops import subtrees_in_use
from instructor_app.document.commands import (
    AddNodeCommand,
    CompoundCommand,
    PlanFieldCommand,
    ReplaceNodeCommand,
)
from instructor_app.document.model import PlanModel

__all__ = [
    "EmbedSubtreesCommand",
    "DropUnusedSubtreesCommand",
    "PasteWithSubtreesCommand",
    "InsertInstanceCommand",
    "UseSavedSubtreeCommand",
    "DetachInstanceCommand",
    "UpdateInstanceCommand",
]


class EmbedSubtreesCommand(PlanFieldCommand):
    """Add to the plan the definitions it does not hold yet (by reference)."""

    FIELD = "subtrees"

    def __init__(self, document: PlanModel, subtrees: list[SubtreeSpec]) -> None:
        have = list(document.plan.subtrees)
        for subtree in subtrees:
            if all(s.ref != subtree.ref for s in have):
                have.append(subtree)
        super().__init__(document, have)


class DropUnusedSubtreesCommand(PlanFieldCommand):
    """Keep only the definitions some instance of the plan still runs.

    What goes is decided when it runs, after its siblings changed the tree.
    """

    FIELD = "subtrees"

    def __init__(self, document: PlanModel) -> None:
        super().__init__(document, document.plan.subtrees)

    def redo(self) -> None:
        plan = self.document.plan
        self.old = list(plan.subtrees)
        kept = subtrees_in_use(plan.tree, plan.subtrees)
        self.new = kept if len(kept) != len(self.old) else self.old  # none goes: order stays
        super().redo()


def _in_place_of(document: PlanModel, node_id: str, node: NodeSpec) -> ReplaceNodeCommand:
    """Put ``node`` where ``node_id`` is, at its canvas position if it was placed by hand."""
    layout = document.plan.layout.get(node_id)
    return ReplaceNodeCommand(document, node_id, node, {node.id: layout} if layout else {})


class PasteWithSubtreesCommand(CompoundCommand):
    """Paste nodes whose instances run definitions the plan lacks: those come too."""

    def __init__(
        self,
        document: PlanModel,
        node: NodeSpec,
        parent_id: str | None,
        index: int,
        layout: dict[str, NodeLayout],
        subtrees: list[SubtreeSpec],
    ) -> None:
        super().__init__(document, f"Paste {node.label}")
        self.add(EmbedSubtreesCommand(document, subtrees))
        self.add(AddNodeCommand(document, node, parent_id, index, layout))


class InsertInstanceCommand(CompoundCommand):
    """Insert an instance of a library subtree, embedding its definition."""

    def __init__(
        self,
        document: PlanModel,
        subtree: SubtreeSpec,
        instance: NodeSpec,
        parent_id: str | None,
        index: int,
    ) -> None:
        super().__init__(document, f"Insert {subtree.name}")
        self.add(EmbedSubtreesCommand(document, [subtree]))
        self.add(AddNodeCommand(document, instance, parent_id, index))


class UseSavedSubtreeCommand(CompoundCommand):
    """Replace nodes just saved as a subtree with an instance of it."""

    def __init__(
        self, document: PlanModel, node_id: str, saved: SubtreeSpec, instance: NodeSpec
    ) -> None:
        original = document.node(node_id)
        super().__init__(document, f"Save {original.label} as the subtree {saved.name}")
        self.add(EmbedSubtreesCommand(document, [saved]))
        self.add(_in_place_of(document, node_id, instance))


class DetachInstanceCommand(CompoundCommand):
    """Turn an instance into plain nodes; a definition no instance runs any more goes."""

    def __init__(self, document: PlanModel, node_id: str, nodes: NodeSpec) -> None:
        super().__init__(document, f"Detach {document.node(node_id).label}")
        self.add(_in_place_of(document, node_id, nodes))
        self.add(DropUnusedSubtreesCommand(document))


class UpdateInstanceCommand(CompoundCommand):
    """Move an instance to another version of its subtree (``updated`` runs ``newer``)."""

    def __init__(
        self, document: PlanModel, node_id: str, newer: SubtreeSpec, updated: NodeSpec
    ) -> None:
        label = document.node(node_id).label
        super().__init__(document, f"Update {label} to version {newer.version}")
        self.add(EmbedSubtreesCommand(document, [newer]))
        self.add(_in_place_of(document, node_id, updated))
        self.add(DropUnusedSubtreesCommand(document))
