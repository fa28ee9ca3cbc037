"""The plan panels: waypoints (record from the arm, import a file, remove) and the plan's
settings (name, run policy). Each change is one undo command that undoes byte for byte.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from capabilities.waypoints import WaypointLibrary
from engine.spec import RunPolicy
from engine.types import JointConfig, Pose, Waypoint, WaypointFrame
from instructor_app.document import PlanDocument
from instructor_app.panels import PlanSettingsPanel, WaypointsPanel
from tests.instructor_app.gui_driver import choose

EXAMPLE_WAYPOINTS = (
    Path(__file__).resolve().parents[3] / "resources" / "examples" / "cup_to_bin.waypoints.json"
)
JOINTS = (0.1, -1.2, 1.3, -1.4, -1.5, 0.6)
TOOL = Pose((0.4, 0.1, 0.3), (1.0, 0.0, 0.0, 0.0))
CUP = Pose((0.5, 0.2, 0.0))


@dataclass
class Seen:
    pose: Pose
    stamp: float = 0.0


class FakeArm:
    def joint_positions(self) -> tuple[float, ...]:
        return JOINTS

    def tcp_pose(self) -> Pose:
        return TOOL


class FakeWorld:
    def best(self, object_class: str, newer_than: float | None = None) -> Seen | None:
        return Seen(CUP) if object_class == "cup" else None


@dataclass
class FakeCell:
    parts: dict[str, Any] = field(default_factory=dict)

    def interfaces(self) -> dict[str, Any]:
        return self.parts


@dataclass
class FakeRegistry:
    cell: FakeCell


def with_arm() -> FakeRegistry:
    return FakeRegistry(FakeCell({"arm": FakeArm(), "world": FakeWorld()}))


@pytest.fixture
def doc(qapp: Any) -> PlanDocument:
    return PlanDocument()


@pytest.fixture
def panel(qtbot: Any, doc: PlanDocument) -> WaypointsPanel:
    widget = WaypointsPanel(doc, with_arm())
    qtbot.addWidget(widget)
    widget.show()
    return widget


def one_undoable_step(doc: PlanDocument, before: str, depth: int) -> None:
    assert doc.undo_stack.count() == depth + 1
    after = doc.serialized()
    doc.undo_stack.undo()
    assert doc.serialized() == before
    doc.undo_stack.redo()
    assert doc.serialized() == after


def test_import_adds_the_files_waypoints_in_one_command(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument
) -> None:
    before, depth = doc.serialized(), doc.undo_stack.count()
    panel.ask_path = lambda parent: str(EXAMPLE_WAYPOINTS)
    messages: list[str] = []
    panel.message.connect(messages.append)
    qtbot.mouseClick(panel.import_button, Qt.MouseButton.LeftButton)
    assert doc.plan.waypoints == list(WaypointLibrary.load(EXAMPLE_WAYPOINTS))
    assert panel.list.count() == 2 and panel.list.item(1).text() == "over bin (object of waste_bin)"
    assert messages == ["Imported 2 waypoints from cup_to_bin.waypoints.json"]
    one_undoable_step(doc, before, depth)
    assert panel.import_file(EXAMPLE_WAYPOINTS) == 2  # the same again: nothing changes
    assert doc.undo_stack.count() == depth + 1


def test_a_bad_waypoint_file_says_why_and_changes_nothing(
    panel: WaypointsPanel, doc: PlanDocument, tmp_path: Path
) -> None:
    bad = tmp_path / "bad.waypoints.json"
    bad.write_text('{"format": "costar-waypoints", "format_version": 1, "waypoints": 3}')
    messages: list[str] = []
    panel.message.connect(messages.append)
    assert panel.import_file(bad) == 0
    assert doc.undo_stack.count() == 0 and doc.plan.waypoints == []
    assert "bad.waypoints.json" in messages[0] and "$.waypoints" in messages[0]


def test_record_takes_the_arms_joints_from_the_typed_name(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument
) -> None:
    before = doc.serialized()
    qtbot.keyClicks(panel.name_field, "observe")
    qtbot.keyClick(panel.name_field, Qt.Key.Key_Return)
    wanted = Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(JOINTS))
    assert doc.plan.waypoints == [wanted] and panel.name_field.text() == ""
    one_undoable_step(doc, before, 0)


def test_record_the_tool_pose_and_a_pose_relative_to_a_seen_object(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument
) -> None:
    assert panel.record("here", "world") == Waypoint("here", pose=TOOL)
    choose(qtbot, panel.frame_combo, "object")
    qtbot.keyClicks(panel.object_field, "cup")
    qtbot.keyClicks(panel.name_field, "above cup")
    qtbot.mouseClick(panel.record_button, Qt.MouseButton.LeftButton)
    smart = doc.plan.waypoints[1]
    assert (smart.name, smart.frame, smart.reference) == ("above cup", WaypointFrame.OBJECT, "cup")
    assert smart.pose is not None
    assert smart.pose.position == pytest.approx((-0.1, -0.1, 0.3))
    assert CUP.compose(smart.pose).position == pytest.approx(TOOL.position)


def test_nothing_is_recorded_without_a_name_an_arm_or_a_seen_object(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument
) -> None:
    messages: list[str] = []
    panel.message.connect(messages.append)
    assert panel.record("  ") is None
    assert panel.record("over bin", "object", "waste_bin") is None
    panel.set_registry(FakeRegistry(FakeCell()))
    assert not panel.record_button.isEnabled()
    assert panel.record("x") is None
    assert doc.undo_stack.count() == 0
    assert [m.split(" ")[0] for m in messages] == ["Type", "The", "This"]


def test_remove_the_selected_waypoint(panel: WaypointsPanel, doc: PlanDocument) -> None:
    panel.import_file(EXAMPLE_WAYPOINTS)
    before = doc.serialized()
    panel.list.setCurrentRow(0)
    panel.remove_button.click()
    assert [w.name for w in doc.plan.waypoints] == ["over bin"]
    one_undoable_step(doc, before, 1)
    doc.undo_stack.undo()
    assert panel.list.count() == 2  # the list follows the document


def test_plan_settings_set_the_name_and_the_run_policy(qtbot: Any, doc: PlanDocument) -> None:
    panel = PlanSettingsPanel(doc)
    qtbot.addWidget(panel)
    panel.show()
    before = doc.serialized()
    choose(qtbot, panel.policy_combo, "until success")
    assert doc.plan.run_policy is RunPolicy.UNTIL_SUCCESS
    one_undoable_step(doc, before, 0)
    panel.name_field.selectAll()
    qtbot.keyClicks(panel.name_field, "Cup to bin")
    qtbot.keyClick(panel.name_field, Qt.Key.Key_Return)
    assert doc.plan.name == "Cup to bin" and doc.undo_stack.count() == 2
    qtbot.keyClick(panel.name_field, Qt.Key.Key_Return)  # unchanged: no command
    assert doc.undo_stack.count() == 2
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert panel.policy_combo.currentText() == "once"
    assert panel.name_field.text() == doc.plan.name


def test_plan_settings_set_the_limit_of_identical_failures(qtbot: Any, doc: PlanDocument) -> None:
    panel = PlanSettingsPanel(doc)
    qtbot.addWidget(panel)
    panel.show()
    spin = panel.give_up_spin
    assert spin.value() == 5 and not spin.isEnabled()  # only for until success
    choose(qtbot, panel.policy_combo, "until success")
    assert spin.isEnabled()
    before = doc.serialized()
    spin.lineEdit().selectAll()
    qtbot.keyClicks(spin, "12")
    qtbot.keyClick(spin, Qt.Key.Key_Return)
    assert doc.plan.give_up_after == 12
    one_undoable_step(doc, before, 1)
    assert doc.undo_stack.undoText() == "Change the plan's limit of identical failures"
    spin.setValue(0)
    assert doc.plan.give_up_after == 0 and spin.text() == "never"
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert spin.value() == 5 and doc.plan.give_up_after == 5
