"""Edits of a document that involve library subtrees, each one undo step.

An instance and the definition it runs travel together: inserting an instance embeds its
subtree in the plan (``PlanSpec.subtrees``); saving nodes as a subtree replaces them with an
instance of it; detaching turns an instance back into plain nodes; updating moves an
instance to the library's newer version. Each pushes one compound command of
:mod:`instructor_app.document.subtree_commands`, so undo restores the plan byte for byte.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

from engine.operations import OperationSource
from engine.spec import Binding, SubtreeSpec
from engine.subtree_ops import (
    OpenPort,
    detach,
    instance_name,
    instance_of,
    make_subtree,
    ports_bound_elsewhere,
    ports_of,
    update,
)
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.document.subtree_commands import (
    DetachInstanceCommand,
    InsertInstanceCommand,
    UpdateInstanceCommand,
    UseSavedSubtreeCommand,
)
from instructor_app.document.tree_ops import can_have_child

__all__ = ["SubtreeEditor"]


class SubtreeEditor:
    """Subtree edits of one document (its undo stack holds them).

    Args:
        document: the document edited.
    """

    def __init__(self, document: PlanDocument) -> None:
        self.document = document

    def insert_instance(
        self,
        subtree: SubtreeSpec,
        parent_id: str | None,
        index: int | None = None,
        params: Mapping[str, Binding] | None = None,
    ) -> str:
        """Insert an instance of a library subtree (its ports unbound but ``params`` and
        those the plan's other instances bind under the same name and type, and named after
        them: "Pick cup"); returns its id.
        """
        doc = self.document
        if parent_id is not None and not can_have_child(doc.node(parent_id)):
            raise DocumentError(f"{doc.node(parent_id).label!r} cannot take another child")
        if parent_id is None and doc.plan.tree is not None:
            raise DocumentError("the plan already has a root node; add the instance under it")
        node = instance_of(subtree)
        params = {**ports_bound_elsewhere(doc.plan, subtree), **(params or {})}
        if params:
            bound = {**node.params, **params}
            node = replace(node, params=bound, name=instance_name(subtree, bound))
        if parent_id is not None and index is None:
            index = len(doc.node(parent_id).children)
        doc.push(InsertInstanceCommand(doc, subtree, node, parent_id, index or 0))
        return node.id

    def save_as_subtree(
        self,
        node_id: str,
        name: str,
        source: OperationSource,
        open_ports: Sequence[OpenPort] = (),
        outputs: Mapping[str, str] | None = None,
        description: str = "",
    ) -> SubtreeSpec:
        """A subtree made from a node and the nodes below it (version 0: not in a library).

        The caller saves it to the library and then calls :meth:`use_saved` to replace the
        nodes with an instance of the saved version.

        Raises:
            DocumentError: a chosen port or output does not fit the nodes.
        """
        doc = self.document
        try:
            return make_subtree(
                doc.node(node_id),
                name,
                ports_of(doc.plan, source),
                open_ports,
                outputs,
                description,
            )
        except ValueError as exc:
            raise DocumentError(str(exc)) from exc

    def use_saved(
        self, node_id: str, saved: SubtreeSpec, open_ports: Sequence[OpenPort] = ()
    ) -> str:
        """Replace a node with an instance of ``saved`` that does what it did, named as the
        subtree (the name chosen when saving); returns its id.
        """
        doc = self.document
        original = doc.node(node_id)
        instance = instance_of(saved, original, open_ports)
        doc.push(UseSavedSubtreeCommand(doc, node_id, saved, instance))
        return instance.id

    def detach(self, node_id: str) -> str:
        """Turn an instance into plain nodes; returns the id of the top one."""
        doc = self.document
        instance = doc.node(node_id)
        try:
            nodes = detach(doc.plan, instance)
        except ValueError as exc:
            raise DocumentError(str(exc)) from exc
        doc.push(DetachInstanceCommand(doc, node_id, nodes))
        return nodes.id

    def update(self, node_id: str, newer: SubtreeSpec) -> None:
        """Move an instance to another version of its subtree, keeping what still fits."""
        doc = self.document
        instance = doc.node(node_id)
        doc.push(UpdateInstanceCommand(doc, node_id, newer, update(instance, newer)))
