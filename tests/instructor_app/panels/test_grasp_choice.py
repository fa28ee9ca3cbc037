"""The inspector lets a user pick a grasp of the object's model by name (gripper.grasp's
``grasp`` port lists the library's grasps; unset means the model's first), and validation
refuses a name that is not one of them.
"""

from __future__ import annotations

from typing import Any

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.gripper import capability as gripper
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ObjectModel, ParamType
from engine.validation import ERROR, validate_plan
from instructor_app.document import PlanDocument
from instructor_app.inspectors.editors import ChoiceEditor
from instructor_app.inspectors.rows import MODE_UNSET, MODE_VALUE
from instructor_app.panels.inspector import InspectorPanel
from tests.instructor_app.gui_driver import choose, choose_index


def _grasp_node(grasp: str | None = None) -> NodeSpec:
    params = {
        "object": Binding.fixed(ObjectModel("cup"), ParamType.OBJECT),
        "pose": Binding.reference("CUP_POSE"),
    }
    if grasp is not None:
        params["grasp"] = Binding.fixed(grasp, ParamType.TEXT)
    return NodeSpec(NodeKind.OPERATION, "grasp CUP", id="grasp", op="gripper.grasp", params=params)


def test_a_grasp_is_picked_by_name_from_a_list(qtbot: Any, qapp: Any) -> None:
    registry = CapabilityRegistry([gripper()], cell=NullCell())
    document = PlanDocument()
    document.add_node(_grasp_node())
    panel = InspectorPanel(document, registry)
    qtbot.addWidget(panel)
    panel.show()
    panel.show_node("grasp")
    row = panel.port_row("grasp")
    assert row.mode == MODE_UNSET  # the model's first grasp
    choose_index(qtbot, row.mode_combo, MODE_VALUE)
    assert isinstance(row.editor, ChoiceEditor)
    offered = [row.editor.combo.itemText(i) for i in range(row.editor.combo.count())]
    assert offered == ["first", "top", "rim", "suction", "weld"]
    choose(qtbot, row.editor.combo, "rim")
    assert document.node("grasp").params["grasp"] == Binding.fixed("rim", ParamType.TEXT)


def test_validation_refuses_a_grasp_name_no_model_has() -> None:
    registry = CapabilityRegistry([gripper()], cell=NullCell())
    problems = validate_plan(PlanSpec(_grasp_node("side"), "p"), registry)
    texts = [p.message for p in problems if p.severity == ERROR]
    assert any("'grasp' of 'grasp CUP' must be one of first, top, rim, suction" in t for t in texts)
