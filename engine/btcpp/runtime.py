"""A plan as BehaviorTree.CPP holds it once loaded: numbered nodes, one tree per instance.

BehaviorTree.CPP's ``WriteTreeToXML(tree, add_metadata=true, ...)`` (what its Groot2
publisher sends) writes a *loaded* tree, not the file it came from: every SubTree instance is
a ``<BehaviorTree ID=".." _fullpath="..">`` of its own, every node has a ``_uid`` (its
number, counted from 1 in the order the nodes were made: depth first, an instance's inside
right after its SubTree node), the SubTree nodes carry the ``_fullpath`` of the instance they
run, and the other nodes a ``name`` (their type when they have none), with their ports and
their pre- and post-conditions. This module makes that
document from our own export (:func:`engine.btcpp.writer.export_xml`), and tells which runtime
node id (:class:`engine.instances.Scope`) has which number, and which blackboard names each
instance sees.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field

from engine.btcpp.errors import XmlExportError
from engine.btcpp.writer import export_xml
from engine.conditions import Condition
from engine.instances import ROOT_SCOPE, Scope
from engine.operations import OperationManifest
from engine.spec import NodeKind, NodeSpec, PlanSpec

__all__ = ["LoadedInstance", "LoadedTree", "loaded_tree"]

# BehaviorTree.CPP writes a node's pre- and post-conditions (_skipIf ...) with its ports; our
# other ``_`` attributes (our ids, the canvas) are not its.
_CONDITIONS = frozenset(condition.attribute for condition in Condition)


@dataclass
class LoadedInstance:
    """One tree instance of a loaded tree (BehaviorTree.CPP's ``Tree::Subtree``).

    Attributes:
        tree_id: the ``<BehaviorTree>`` it runs.
        path: its ``_fullpath`` ("" for the main tree; else the path of SubTree names).
        names: the prefix of the blackboard names private to it (:class:`Scope`).
        uids: the numbers of its nodes, in the order they were made.
    """

    tree_id: str
    path: str
    names: str
    uids: list[int] = field(default_factory=list)

    @property
    def blackboard_name(self) -> str:
        """The name a Groot2 blackboard request gives it: its path, the tree id for the main."""
        return self.path or self.tree_id


@dataclass(frozen=True)
class LoadedTree:
    """The loaded tree's XML, and the numbers of its nodes.

    Attributes:
        xml: the document, as ``WriteTreeToXML`` with metadata writes it.
        uids: runtime node id -> ``_uid``.
        instances: the main tree first, then every instance in the order it was made.
    """

    xml: str
    uids: dict[str, int]
    instances: tuple[LoadedInstance, ...]

    @property
    def order(self) -> list[int]:
        """Every ``_uid``, instance by instance, as BehaviorTree.CPP lists its nodes."""
        return [uid for instance in self.instances for uid in instance.uids]


class _Loader:
    def __init__(self, plan: PlanSpec, trees: Mapping[str, ET.Element]) -> None:
        self.plan = plan
        self.trees = trees
        self.root = ET.Element("root", {"BTCPP_format": "4"})
        self.uids: dict[str, int] = {}
        self.instances: list[LoadedInstance] = []
        self.count = 0

    def instance(self, tree_id: str, path: str, spec: NodeSpec, scope: Scope) -> None:
        source = self.trees.get(tree_id)
        if source is None or len(source) == 0:
            raise XmlExportError(self.plan.name or "<plan>", path or tree_id, "a tree", "none")
        element = ET.SubElement(self.root, "BehaviorTree", {"ID": tree_id, "_fullpath": path})
        instance = LoadedInstance(tree_id, path, scope.names)
        self.instances.append(instance)
        self.node(spec, source[0], element, instance, scope)

    def node(
        self,
        spec: NodeSpec,
        source: ET.Element,
        parent: ET.Element,
        instance: LoadedInstance,
        scope: Scope,
    ) -> None:
        self.count += 1
        uid = self.count
        self.uids[scope.node_id(spec.id)] = uid
        instance.uids.append(uid)
        element = ET.SubElement(parent, source.tag)
        sub = spec.subtree and self.plan.subtree(spec.subtree)
        inner_path = ""
        if spec.kind is NodeKind.SUBTREE and sub:
            tree_id = source.get("ID", "")
            own = source.get("name") or f"{tree_id}::{uid}"
            inner_path = f"{instance.path}/{own}" if instance.path else own
            element.set("ID", tree_id)
            element.set("_fullpath", inner_path)
        else:
            element.set("name", source.get("name") or source.tag)
        element.set("_uid", str(uid))
        for key, value in source.attrib.items():
            if key not in ("ID", "name") and (not key.startswith("_") or key in _CONDITIONS):
                element.set(key, value)
        if spec.kind is NodeKind.SUBTREE and sub:
            self.instance(element.get("ID", ""), inner_path, sub.tree, scope.inside(spec, sub))
            return
        if len(source) != len(spec.children):
            raise XmlExportError(
                self.plan.name or "<plan>",
                spec.label,
                f"{len(spec.children)} child elements",
                str(len(source)),
            )
        for child, child_source in zip(spec.children, source, strict=True):
            self.node(child, child_source, element, instance, scope)


def loaded_tree(plan: PlanSpec, manifests: Mapping[str, OperationManifest]) -> LoadedTree:
    """The plan as BehaviorTree.CPP would hold it after loading our export of it.

    Args:
        plan: the plan (with a tree).
        manifests: operation id -> manifest, for the TreeNodesModel (as for ``export_xml``).

    Raises:
        XmlExportError: what ``export_xml`` refuses.
    """
    exported = ET.fromstring(export_xml(plan, manifests))
    trees = {tree.get("ID", ""): tree for tree in exported.iter("BehaviorTree")}
    assert plan.tree is not None  # export_xml refused a plan without one
    loader = _Loader(plan, trees)
    loader.instance(exported.get("main_tree_to_execute", ""), "", plan.tree, ROOT_SCOPE)
    models = exported.find("TreeNodesModel")
    loader.root.append(models if models is not None else ET.Element("TreeNodesModel"))
    ET.indent(loader.root, space="  ")
    xml = ET.tostring(loader.root, encoding="unicode", short_empty_elements=True)
    return LoadedTree(xml, loader.uids, tuple(loader.instances))
