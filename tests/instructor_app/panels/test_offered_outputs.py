"""A query's output is offered first for the next node's input of its type (issue 26): the
parameter field lists the outputs of that type written by the nodes before it, the nearest
first (those of a node naming the same object before the rest); choosing "parameter" binds
the first offer in one undo step; a fresh node's required input is bound to the one output
of its type before it, when there is exactly one.
"""

from __future__ import annotations

from typing import Any

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.gripper import capability as gripper
from capabilities.markers import capability as markers
from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ObjectModel, ParamType
from instructor_app.document import PlanDocument
from instructor_app.inspectors.offers import nodes_before_insert, offered_outputs, prebound
from instructor_app.inspectors.rows import MODE_REFERENCE
from instructor_app.panels.inspector import InspectorPanel
from tests.instructor_app.gui_driver import choose_index


def _registry() -> CapabilityRegistry:
    return CapabilityRegistry([markers(), gripper()], cell=NullCell())


def _object(name: str) -> Binding:
    return Binding.fixed(ObjectModel(name), ParamType.OBJECT)


def _pose_of(node_id: str, obj: str, name: str) -> NodeSpec:
    params = {"object": _object(obj), "pose": Binding.reference(name)}
    return NodeSpec(NodeKind.OPERATION, f"pose of {obj}", id=node_id, op="markers.object_pose",
                    params=params)  # fmt: skip


def _document() -> PlanDocument:
    """Sequence[pose of cup -> CUP_POSE, pose of bin -> BIN_POSE, grasp, pose of box]."""
    doc = PlanDocument()
    root = doc.add_node(NodeSpec(NodeKind.SEQUENCE, "Main", id="root"))
    doc.add_node(_pose_of("cup", "cup", "CUP_POSE"), root)
    doc.add_node(_pose_of("bin", "waste_bin", "BIN_POSE"), root)
    doc.add_node(NodeSpec(NodeKind.OPERATION, "grasp", id="grasp", op="gripper.grasp"), root)
    doc.add_node(_pose_of("box", "box", "BOX_POSE"), root)  # after the grasp: never offered
    doc.undo_stack.clear()
    return doc


def _panel(qtbot: Any, doc: PlanDocument) -> InspectorPanel:
    panel = InspectorPanel(doc, _registry())
    qtbot.addWidget(panel)
    panel.show()
    panel.show_node("grasp")
    return panel


def test_the_outputs_before_a_node_are_offered_first_nearest_first(qtbot: Any, qapp: Any) -> None:
    doc = _document()
    panel = _panel(qtbot, doc)
    row = panel.port_row("pose")
    assert row.offers == ["BIN_POSE", "CUP_POSE"]
    assert row.reference_choices() == ["BIN_POSE", "CUP_POSE", "BOX_POSE"]
    assert panel.port_row("object").offers == []  # no output of an object model before it


def test_the_output_about_the_same_object_comes_first(qtbot: Any, qapp: Any) -> None:
    doc = _document()
    panel = _panel(qtbot, doc)
    doc.set_param("grasp", "object", _object("cup"))  # the offers follow the document
    assert panel.port_row("pose").offers == ["CUP_POSE", "BIN_POSE"]


def test_choosing_parameter_binds_the_first_offer_in_one_step(qtbot: Any, qapp: Any) -> None:
    doc = _document()
    doc.set_param("grasp", "object", _object("cup"))
    panel = _panel(qtbot, doc)
    steps = doc.undo_stack.count()
    row = panel.port_row("pose")
    choose_index(qtbot, row.mode_combo, MODE_REFERENCE)
    assert doc.node("grasp").params["pose"] == Binding.reference("CUP_POSE")
    assert row.ref_field.text() == "CUP_POSE"
    assert doc.undo_stack.count() == steps + 1
    doc.undo_stack.undo()
    assert "pose" not in doc.node("grasp").params


def test_a_fresh_nodes_required_input_takes_the_one_output_of_its_type(qapp: Any) -> None:
    registry = _registry()
    manifest = registry.manifest("gripper.grasp")
    doc = _document()
    plan = doc.plan
    fresh = NodeSpec(NodeKind.OPERATION, "grasp", op="gripper.grasp")
    after_cup = nodes_before_insert(plan, "root", 1)
    assert [n.id for n in after_cup] == ["root", "cup"]
    bound = prebound(fresh, manifest, plan, registry, after_cup)
    assert bound.params == {"pose": Binding.reference("CUP_POSE")}  # the only pose before it
    after_bin = nodes_before_insert(plan, "root", 2)
    assert offered_outputs(plan, registry, after_bin, (ParamType.POSE,)) == ["BIN_POSE",
                                                                             "CUP_POSE"]  # fmt: skip
    assert prebound(fresh, manifest, plan, registry, after_bin) is fresh  # two: the user picks
    assert [n.id for n in nodes_before_insert(plan, "root", None)] == [
        "root", "cup", "bin", "grasp", "box",
    ]  # fmt: skip
