"""The validation panel lists problems after edits pause and leads to the node."""

from __future__ import annotations

from pytestqt.qtbot import QtBot

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.debug import capability as debug_capability
from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ParamType, Pose
from instructor_app.document import PlanDocument
from instructor_app.panels.validation import ValidationPanel


def test_lists_problems_with_path_and_severity(
    qtbot: QtBot, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    panel = ValidationPanel(document, registry)
    qtbot.addWidget(panel)
    problems = panel.problems()
    assert any(
        p.node_id == "move" and p.field == "target" and p.severity == "error" for p in problems
    )
    assert any(p.node_id == "query" and p.severity == "warning" for p in problems)
    assert panel.list.topLevelItemCount() == len(problems)
    first = panel.list.topLevelItem(0)
    assert first.text(1).startswith("Main/")
    assert first.text(2) == problems[0].message


def test_revalidates_once_after_edits_pause(
    qtbot: QtBot, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    panel = ValidationPanel(document, registry)
    qtbot.addWidget(panel)
    summaries: list[tuple[int, int]] = []
    panel.summary_changed.connect(lambda e, w: summaries.append((e, w)))
    document.set_param("move", "target", Binding.fixed(Pose(), ParamType.POSE))
    document.set_param("query", "value", Binding.fixed(1.0, ParamType.NUMBER))
    document.set_param("query", "result", Binding.reference("X"))
    assert panel.pending() and summaries == []
    with qtbot.waitSignal(panel.summary_changed, timeout=2000) as blocker:
        pass
    assert blocker.args == [0, 0]
    assert summaries == [(0, 0)] and panel.problems() == []


def test_selecting_a_problem_emits_its_node(
    qtbot: QtBot, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    panel = ValidationPanel(document, registry)
    qtbot.addWidget(panel)
    index = next(i for i, p in enumerate(panel.problems()) if p.node_id == "move")
    with qtbot.waitSignal(panel.node_selected) as blocker:
        panel.list.setCurrentItem(panel.list.topLevelItem(index))
    assert blocker.args == ["move"]


def test_unavailable_operation_and_registry_change(
    qtbot: QtBot, document: PlanDocument, registry: CapabilityRegistry
) -> None:
    document.add_node(
        NodeSpec(NodeKind.OPERATION, "Lamp", id="lamp", op="template.lamp_is_lit"), "root"
    )
    panel = ValidationPanel(document, registry)
    qtbot.addWidget(panel)
    lamp = [p for p in panel.problems() if p.node_id == "lamp"]
    assert lamp and "cannot run on this cell" in lamp[0].message
    assert not panel.list.topLevelItem(0).icon(0).isNull()
    with qtbot.waitSignal(panel.summary_changed):
        panel.set_registry(CapabilityRegistry([debug_capability()], cell=NullCell()))
    lamp = [p for p in panel.problems() if p.node_id == "lamp"]
    assert lamp and "There is no operation" in lamp[0].message
