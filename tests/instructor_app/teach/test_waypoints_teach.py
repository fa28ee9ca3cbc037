"""Teaching waypoints without a robot (a fake arm and world model): Record relative to the
nearest recognised object or marker, rename and edit numbers in the list, Teach again, and
the inspector's Teach under Pose and Waypoint parameters. Every change is one undo step
that undoes byte for byte, and nodes using a waypoint follow its changes.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
from PySide6.QtCore import Qt

from capabilities.base import CapabilityRegistry
from capabilities.motion import capability as motion_capability
from capabilities.world_model import Detection, WorldModel
from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ParamType, Pose, Waypoint, WaypointFrame
from instructor_app.document import PlanDocument
from instructor_app.panels import InspectorPanel, WaypointsPanel
from instructor_app.runtime.teach import RobotTeacher
from tests.instructor_app.gui_driver import ScriptedDialogs, choose

JOINTS = (0.1, -1.2, 1.3, -1.4, -1.5, 0.6)
DOWN = (1.0, 0.0, 0.0, 0.0)
TOOL = Pose((0.5, 0.1, 0.3), DOWN)


@dataclass
class FakeArm:
    tool: Pose = TOOL

    def joint_positions(self) -> tuple[float, ...]:
        return JOINTS

    def tcp_pose(self) -> Pose:
        return self.tool


@dataclass
class FakeCell:
    parts: dict[str, Any] = field(default_factory=dict)

    def interfaces(self) -> dict[str, Any]:
        return self.parts

    def clock(self) -> float:
        return 0.0


def seen_world() -> WorldModel:
    """A cup under the tool, a bin farther off; marker 7 near the tool, marker 3 far."""
    world = WorldModel()
    world.replace(
        "test",
        [
            Detection("waste_bin", Pose((0.2, -0.4, 0.0)), 0.9, 0.0, "test"),
            Detection("cup", Pose((0.52, 0.1, 0.0)), 0.8, 0.0, "test"),
        ],
    )
    world.set_markers({7: Pose((0.5, 0.15, 0.0)), 3: Pose((-0.3, 0.3, 0.0))}, 0.0)
    return world


@pytest.fixture
def cell() -> FakeCell:
    return FakeCell({"arm": FakeArm(), "world": seen_world()})


@pytest.fixture
def teacher(qapp: Any, cell: FakeCell) -> Iterator[RobotTeacher]:
    robot = RobotTeacher(CapabilityRegistry([motion_capability()], cell=cell))
    yield robot
    robot.shutdown()


@pytest.fixture
def doc(qapp: Any) -> PlanDocument:
    return PlanDocument()


@pytest.fixture
def panel(qtbot: Any, doc: PlanDocument, teacher: RobotTeacher, cell: FakeCell) -> WaypointsPanel:
    widget = WaypointsPanel(doc, CapabilityRegistry([], cell=cell), teacher=teacher)
    qtbot.addWidget(widget)
    widget.show()
    return widget


def undoes_exactly(doc: PlanDocument, before: str) -> None:
    after = doc.serialized()
    doc.undo_stack.undo()
    assert doc.serialized() == before
    doc.undo_stack.redo()
    assert doc.serialized() == after


def record(qtbot: Any, panel: WaypointsPanel, name: str, frame: str) -> Waypoint:
    choose(qtbot, panel.frame_combo, frame)
    qtbot.keyClicks(panel.name_field, name)
    qtbot.mouseClick(panel.record_button, Qt.MouseButton.LeftButton)
    return next(w for w in panel.document.plan.waypoints if w.name == name)


def test_record_relative_to_the_nearest_recognised_object_and_marker(
    qtbot: Any, panel: WaypointsPanel, cell: FakeCell
) -> None:
    smart = record(qtbot, panel, "above cup", "object")
    assert (smart.frame, smart.reference) == (WaypointFrame.OBJECT, "cup")  # the nearer one
    assert smart.pose is not None and smart.pose.position == pytest.approx((-0.02, 0.0, 0.3))
    by_marker = record(qtbot, panel, "at marker", "marker")
    assert (by_marker.frame, by_marker.reference) == (WaypointFrame.MARKER, "7")
    assert Pose((0.5, 0.15, 0.0)).compose(by_marker.pose).position == pytest.approx(
        cell.parts["arm"].tool.position
    )
    qtbot.keyClicks(panel.object_field, "waste_bin")  # named: that one, near or not
    named = record(qtbot, panel, "over bin", "object")
    assert named.reference == "waste_bin"
    assert panel.list.currentItem().text() == "over bin (object of waste_bin)"
    assert panel.details.name_edit.text() == "over bin"


def test_nothing_recognised_says_so(qtbot: Any, panel: WaypointsPanel, cell: FakeCell) -> None:
    cell.parts["world"].clear()
    messages: list[str] = []
    panel.message.connect(messages.append)
    assert panel.record("x", "object") is None and panel.record("y", "marker") is None
    assert messages == [
        "The cell has not recognised any object: detect first.",
        "The cell has not recognised any marker: detect first.",
    ]


def plan_using(doc: PlanDocument, waypoint: Waypoint) -> str:
    root = doc.add_node(NodeSpec(NodeKind.SEQUENCE, "Main"))
    return doc.add_node(
        NodeSpec(
            NodeKind.OPERATION,
            "go",
            op="motion.move_to",
            params={"target": Binding.fixed(waypoint, ParamType.WAYPOINT)},
        ),
        root,
    )


def test_rename_and_edit_numbers_change_the_nodes_using_the_waypoint(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument
) -> None:
    taught = record(qtbot, panel, "pick", "world")
    node_id = plan_using(doc, taught)
    before = doc.serialized()
    panel.details.name_edit.setFocus()
    panel.details.name_edit.selectAll()
    qtbot.keyClicks(panel.details.name_edit, "pick plate")
    qtbot.keyClick(panel.details.name_edit, Qt.Key.Key_Return)
    assert [w.name for w in doc.plan.waypoints] == ["pick plate"]
    assert doc.node(node_id).params["target"].value.name == "pick plate"
    undoes_exactly(doc, before)  # the list and the node: one undo step
    before = doc.serialized()
    spin = panel.details.pose_editor.position_spins[2]
    spin.setValue(250.0)  # z in mm
    spin.editingFinished.emit()
    moved = doc.plan.waypoints[0]
    assert moved.pose is not None and moved.pose.position[2] == pytest.approx(0.25)
    assert moved.pose.position[:2] == taught.pose.position[:2]  # type: ignore[union-attr]
    assert doc.node(node_id).params["target"].value == moved
    undoes_exactly(doc, before)


def test_a_name_taken_is_refused(qtbot: Any, panel: WaypointsPanel, doc: PlanDocument) -> None:
    record(qtbot, panel, "a", "world")
    record(qtbot, panel, "b", "joints")
    depth = doc.undo_stack.count()
    messages: list[str] = []
    panel.message.connect(messages.append)
    panel.details.name_edit.setText("a")
    panel.details.name_edit.editingFinished.emit()
    assert [w.name for w in doc.plan.waypoints] == ["a", "b"] and doc.undo_stack.count() == depth
    assert "already a waypoint 'a'" in messages[-1]
    assert panel.details.name_edit.text() == "b"


def test_teach_again_keeps_frame_and_reference(
    qtbot: Any, panel: WaypointsPanel, doc: PlanDocument, cell: FakeCell
) -> None:
    record(qtbot, panel, "above cup", "object")
    cell.parts["arm"].tool = Pose((0.52, 0.1, 0.2), DOWN)
    before = doc.serialized()
    qtbot.mouseClick(panel.teach_button, Qt.MouseButton.LeftButton)
    again = doc.plan.waypoints[0]
    assert (again.frame, again.reference) == (WaypointFrame.OBJECT, "cup")
    assert again.pose is not None and again.pose.position == pytest.approx((0.0, 0.0, 0.2))
    undoes_exactly(doc, before)


@pytest.fixture
def inspector(qtbot: Any, doc: PlanDocument, teacher: RobotTeacher) -> InspectorPanel:
    registry = CapabilityRegistry([motion_capability()], cell=FakeCell())
    widget = InspectorPanel(doc, registry)
    widget.set_teacher(teacher)
    qtbot.addWidget(widget)
    widget.show()
    return widget


def test_inspector_teach_fills_a_pose_and_teaches_a_waypoint_again(
    qtbot: Any, doc: PlanDocument, inspector: InspectorPanel, cell: FakeCell
) -> None:
    smart = Waypoint("above cup", WaypointFrame.OBJECT, Pose((0.0, 0.0, 0.1), DOWN), None, "cup")
    doc.store_waypoints([smart])
    node_id = plan_using(doc, smart)
    inspector.show_node(node_id)
    assert set(inspector.teach_buttons) == {"target", "reference"}  # Pose or Waypoint ports
    before = doc.serialized()
    qtbot.mouseClick(inspector.teach_buttons["target"].teach_button, Qt.MouseButton.LeftButton)
    taught = doc.node(node_id).params["target"].value
    assert (taught.name, taught.frame, taught.reference) == (
        "above cup",
        WaypointFrame.OBJECT,
        "cup",
    )
    assert taught.pose.position == pytest.approx((-0.02, 0.0, 0.3))
    assert doc.plan.waypoints == [taught]  # the plan's list follows
    undoes_exactly(doc, before)
    qtbot.mouseClick(inspector.teach_buttons["reference"].teach_button, Qt.MouseButton.LeftButton)
    assert doc.node(node_id).params["reference"] == Binding.fixed(
        cell.parts["arm"].tool, ParamType.POSE
    )


def test_inspector_teach_on_an_unset_waypoint_makes_one_named_after_the_node(
    qtbot: Any, doc: PlanDocument, inspector: InspectorPanel
) -> None:
    root = doc.add_node(NodeSpec(NodeKind.SEQUENCE, "Main"))
    node_id = doc.add_node(NodeSpec(NodeKind.OPERATION, "over bin", op="motion.move_to"), root)
    doc.store_waypoints([Waypoint("over bin", pose=Pose())])
    inspector.show_node(node_id)
    assert not inspector.teach_buttons["target"].move_button.isEnabled()  # nothing to go to
    qtbot.mouseClick(inspector.teach_buttons["target"].teach_button, Qt.MouseButton.LeftButton)
    made = doc.node(node_id).params["target"].value
    assert made.name == "over bin 2" and made.frame is WaypointFrame.WORLD
    assert [w.name for w in doc.plan.waypoints] == ["over bin", "over bin 2"]
    assert inspector.teach_buttons["target"].move_button.isEnabled()
    doc.undo_stack.undo()
    assert "target" not in doc.node(node_id).params and len(doc.plan.waypoints) == 1
    assert math.isfinite(made.pose.position[0])


def test_inspector_teach_says_what_it_changed_and_asks_before_a_shared_waypoint(
    qtbot: Any, doc: PlanDocument, inspector: InspectorPanel, teacher: RobotTeacher
) -> None:
    """Issue 26: Teach overwrote the shared 'observe' waypoint with no sign."""
    observe = Waypoint("observe", WaypointFrame.WORLD, Pose((0.4, 0.0, 0.5), DOWN))
    doc.store_waypoints([observe])
    first = plan_using(doc, observe)
    root = doc.plan.tree.id  # type: ignore[union-attr]
    params = {"target": Binding.fixed(observe, ParamType.WAYPOINT)}
    doc.add_node(
        NodeSpec(NodeKind.OPERATION, "look again", op="motion.move_to", params=params), root
    )
    dialogs = ScriptedDialogs()
    inspector.dialogs = dialogs
    inspector.show_node(first)
    before = doc.serialized()
    teach = inspector.teach_buttons["target"].teach_button

    dialogs.overwrite_answers = [False]  # "used by 'look again' too: teach it again?" No.
    with qtbot.waitSignal(teacher.message) as said:
        qtbot.mouseClick(teach, Qt.MouseButton.LeftButton)
    assert dialogs.asked == [("overwrite", "observe: look again")]
    assert "cancelled" in said.args[0] and doc.serialized() == before

    dialogs.overwrite_answers = [True]
    with qtbot.waitSignal(teacher.message) as said:
        qtbot.mouseClick(teach, Qt.MouseButton.LeftButton)
    assert len(dialogs.asked) == 2
    assert said.args[0] == (
        "Taught the waypoint 'observe': (400.0, 0.0, 500.0) mm, (180.0, 0.0, 0.0)° → "
        "(500.0, 100.0, 300.0) mm, (180.0, 0.0, 0.0)°. Undo: Ctrl+Z."
    )
    assert doc.plan.waypoints[0].pose == TOOL
    assert all(
        node.params["target"].value.pose == TOOL
        for _, node in doc.plan.walk()
        if "target" in node.params
    )
    undoes_exactly(doc, before)  # one step on the undo stack


def test_inspector_teach_of_a_waypoint_only_this_node_uses_asks_nothing(
    qtbot: Any, doc: PlanDocument, inspector: InspectorPanel, teacher: RobotTeacher
) -> None:
    mine = Waypoint("mine", WaypointFrame.WORLD, Pose((0.4, 0.0, 0.5), DOWN))
    doc.store_waypoints([mine])
    node_id = plan_using(doc, mine)
    dialogs = ScriptedDialogs()
    inspector.dialogs = dialogs
    inspector.show_node(node_id)
    with qtbot.waitSignal(teacher.message) as said:
        qtbot.mouseClick(inspector.teach_buttons["target"].teach_button, Qt.MouseButton.LeftButton)
    assert dialogs.asked == [] and said.args[0].startswith("Taught the waypoint 'mine': (400.0")
    with qtbot.waitSignal(teacher.message) as said:
        qtbot.mouseClick(
            inspector.teach_buttons["reference"].teach_button, Qt.MouseButton.LeftButton
        )
    assert said.args[0] == (
        "Taught reference of go: unset → (500.0, 100.0, 300.0) mm, (180.0, 0.0, 0.0)°. Undo: Ctrl+Z."
    )
