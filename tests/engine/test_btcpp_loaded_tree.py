"""The tree as BehaviorTree.CPP holds it once loaded (what its Groot2 publisher sends)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

from capabilities.base import CapabilityRegistry
from engine.btcpp.runtime import loaded_tree
from engine.build import ROOT_ID, build_tree
from engine.conditions import Condition
from engine.files import load_plan
from engine.spec import NodeKind, NodeSpec, PlanSpec
from resources import resource_path


def _manifests(registry: CapabilityRegistry) -> dict[str, Any]:
    return {m.id: m for m in registry.manifests()}


def _subtree_plan() -> PlanSpec:
    return load_plan(str(resource_path("examples/nodes/subtree.costar.json")))


def test_every_node_has_a_uid_counted_from_one_depth_first_through_instances(
    registry: CapabilityRegistry,
) -> None:
    loaded = loaded_tree(_subtree_plan(), _manifests(registry))
    root = ET.fromstring(loaded.xml)
    trees = root.findall("BehaviorTree")
    nodes = [node for tree in trees for node in tree.iter() if node.tag != "BehaviorTree"]
    assert all(node.get("_uid") for node in nodes)
    assert sorted(int(node.get("_uid", "")) for node in nodes) == list(range(1, 12))
    # The main tree, then one tree per instance, its inside numbered right after its SubTree.
    assert [(t.get("ID"), t.get("_fullpath")) for t in trees] == [
        ("Subtree_instances", ""),
        ("Go_to", "left"),
        ("Go_to", "right"),
    ]
    left, right = trees[0].iter("SubTree")
    assert (left.get("_uid"), left.get("_fullpath")) == ("2", "left")
    assert (right.get("_uid"), right.get("_fullpath")) == ("7", "right")
    assert [n.get("_uid") for n in trees[1].iter()][1:] == ["3", "4", "5", "6"]
    assert root.find("TreeNodesModel/Action[@ID='debug__pretend_move']") is not None
    assert root.find("CostarPlan") is None
    assert loaded.order == [1, 2, 7, 3, 4, 5, 6, 8, 9, 10, 11]


def test_the_numbers_cover_every_runtime_node_but_the_root(registry: CapabilityRegistry) -> None:
    plan = _subtree_plan()
    loaded = loaded_tree(plan, _manifests(registry))
    tree = build_tree(plan, registry)
    assert set(loaded.uids) == set(tree.nodes) - {ROOT_ID}
    names = {i.blackboard_name: i.names for i in loaded.instances}
    assert names["Subtree_instances"] == ""
    assert names["left"].startswith("left#")


def test_nodes_without_a_name_are_named_by_their_type_and_private_attributes_go(
    registry: CapabilityRegistry,
) -> None:
    plan = PlanSpec(
        NodeSpec(NodeKind.SEQUENCE, children=[NodeSpec(NodeKind.OPERATION, op="debug.succeed")]),
        "unnamed",
    )
    root = ET.fromstring(loaded_tree(plan, _manifests(registry)).xml)
    sequence = root.find("BehaviorTree/Sequence")
    assert sequence is not None
    assert sequence.get("name") == "Sequence"
    assert sorted(sequence.attrib) == ["_uid", "name"]
    leaf = sequence.find("debug__succeed")
    assert leaf is not None and leaf.get("name") == "debug__succeed"


def test_pre_and_post_conditions_stay_as_btcpp_writes_them(registry: CapabilityRegistry) -> None:
    leaf = NodeSpec(NodeKind.OPERATION, op="debug.succeed")
    leaf.conditions = {Condition.SKIP_IF: "done == true", Condition.POST: "count += 1"}
    root = ET.fromstring(loaded_tree(PlanSpec(leaf, "kept"), _manifests(registry)).xml)
    element = root.find("BehaviorTree/debug__succeed")
    assert element is not None
    assert (element.get("_skipIf"), element.get("_post")) == ("done == true", "count += 1")
