"""Every editor round-trips its value, converts units and commits once per finished edit."""

from __future__ import annotations

import math
from typing import Any

import pytest
from PySide6.QtCore import Qt
from pytestqt.qtbot import QtBot

from engine.operations import PortSpec
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Region, Waypoint
from engine.units import rpy_to_quaternion
from instructor_app.inspectors import EDITOR_TYPES, EditorContext, concrete_types, editor_for
from instructor_app.inspectors.editors import ChoiceEditor, NumberEditor

WAYPOINTS = (Waypoint("above", pose=Pose((0.1, 0, 0.3))), Waypoint("home", pose=Pose()))
CONTEXT = EditorContext(("cup", "waste_bin"), WAYPOINTS)

VALUES: dict[ParamType, Any] = {
    ParamType.NUMBER: 0.4321,
    ParamType.DURATION: 2.5,
    ParamType.TEXT: "hello",
    ParamType.BOOL: True,
    ParamType.OBJECT: ObjectModel("waste_bin"),
    ParamType.WAYPOINT: WAYPOINTS[1],
    ParamType.POSE: Pose((0.1, 0.2, 0.3), rpy_to_quaternion(0.1, 0.2, 0.3)),
    ParamType.REGION: Region((0.5, 0.0, 0.2), 0.07),
    ParamType.JOINTS: JointConfig((0.1, -1.2, 1.3, -0.4, 1.5, 0.6)),
}


def _committed(qtbot: QtBot, editor: Any) -> list[Any]:
    got: list[Any] = []
    editor.value_committed.connect(got.append)
    return got


@pytest.mark.parametrize("ptype", list(EDITOR_TYPES))
def test_every_type_round_trips_without_emitting(qtbot: QtBot, ptype: ParamType) -> None:
    editor = editor_for(ptype, None, CONTEXT)
    qtbot.addWidget(editor)
    got = _committed(qtbot, editor)
    editor.set_value(VALUES[ptype])
    assert editor.value() == VALUES[ptype]
    assert got == []


def test_number_with_metre_unit_shows_mm(qtbot: QtBot) -> None:
    port = PortSpec("dx", (ParamType.NUMBER,), default=0.0, unit="m")
    editor = editor_for(ParamType.NUMBER, port)
    qtbot.addWidget(editor)
    assert isinstance(editor, NumberEditor) and editor.spin.suffix() == " mm"
    editor.set_value(0.25)
    assert editor.spin.value() == pytest.approx(250.0)
    got = _committed(qtbot, editor)
    editor.spin.lineEdit().selectAll()
    qtbot.keyClicks(editor.spin, "123")
    assert got == []  # nothing per keystroke
    qtbot.keyClick(editor.spin, Qt.Key.Key_Return)
    assert got == [pytest.approx(0.123)]
    assert editor.value() == pytest.approx(0.123)


def test_number_with_radian_unit_shows_degrees_and_keeps_exact_value(qtbot: QtBot) -> None:
    port = PortSpec("tolerance", (ParamType.NUMBER,), default=0.01, unit="rad")
    editor = editor_for(ParamType.NUMBER, port)
    qtbot.addWidget(editor)
    assert editor.value() == 0.01  # the port's default, exactly
    assert editor.spin.value() == pytest.approx(math.degrees(0.01), abs=1e-3)
    got = _committed(qtbot, editor)
    editor.spin.setValue(90.0)  # as the arrows or Enter would
    assert got == [pytest.approx(math.pi / 2)]


def test_duration_is_not_negative(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.DURATION)
    qtbot.addWidget(editor)
    assert editor.spin.minimum() == 0.0 and editor.value() == 1.0


def test_text_commits_on_enter_once(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.TEXT)
    qtbot.addWidget(editor)
    got = _committed(qtbot, editor)
    qtbot.keyClicks(editor.line, "CUP")
    assert got == []
    qtbot.keyClick(editor.line, Qt.Key.Key_Return)
    editor.line.editingFinished.emit()  # focus out after Enter: no second commit
    assert got == ["CUP"]


def test_text_with_choices_is_a_combo(qtbot: QtBot) -> None:
    port = PortSpec("mode", (ParamType.TEXT,), default="joint", choices=("joint", "linear"))
    editor = editor_for(ParamType.TEXT, port)
    qtbot.addWidget(editor)
    assert isinstance(editor, ChoiceEditor) and editor.value() == "joint"
    got = _committed(qtbot, editor)
    editor.combo.setCurrentIndex(1)
    editor.combo.activated.emit(1)
    assert got == ["linear"]


def test_bool_commits_on_toggle(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.BOOL)
    qtbot.addWidget(editor)
    got = _committed(qtbot, editor)
    editor.check.click()
    assert got == [True]


def test_object_model_offers_library_names(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.OBJECT, None, CONTEXT)
    qtbot.addWidget(editor)
    assert [editor.combo.itemText(i) for i in range(editor.combo.count())] == ["cup", "waste_bin"]
    assert editor.value() == ObjectModel("cup")
    got = _committed(qtbot, editor)
    editor.combo.setCurrentIndex(1)
    editor.combo.activated.emit(1)
    assert got == [ObjectModel("waste_bin")]


def test_waypoint_offers_plan_waypoints_and_keeps_unknown_one(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.WAYPOINT, None, CONTEXT)
    qtbot.addWidget(editor)
    assert editor.combo.count() == 2 and editor.value() == WAYPOINTS[0]
    got = _committed(qtbot, editor)
    editor.combo.setCurrentIndex(1)
    editor.combo.activated.emit(1)
    assert got == [WAYPOINTS[1]]
    gone = Waypoint("gone", pose=Pose())
    editor.set_value(gone)
    assert editor.value() == gone and "gone" in editor.combo.currentText()
    empty = editor_for(ParamType.WAYPOINT)
    qtbot.addWidget(empty)
    assert empty.value() is None


def test_pose_editor_converts_and_keeps_untouched_parts(qtbot: QtBot) -> None:
    pose = VALUES[ParamType.POSE]
    editor = editor_for(ParamType.POSE)
    qtbot.addWidget(editor)
    editor.set_value(pose)
    shown = [s.value() for s in editor.position_spins + editor.angle_spins]
    expected = [100.0, 200.0, 300.0, *(math.degrees(a) for a in (0.1, 0.2, 0.3))]
    assert shown == pytest.approx(expected, abs=1e-3)
    got = _committed(qtbot, editor)
    editor.position_spins[0].setValue(150.0)
    assert got[-1].position == pytest.approx((0.15, 0.2, 0.3))
    assert got[-1].position[1:] == pose.position[1:] and got[-1].orientation == pose.orientation
    editor.angle_spins[2].setValue(90.0)
    expected_q = rpy_to_quaternion(0.1, 0.2, math.pi / 2)
    assert got[-1].orientation == pytest.approx(expected_q, abs=1e-12)
    assert len(got) == 2


def test_region_editor_in_mm(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.REGION)
    qtbot.addWidget(editor)
    editor.set_value(VALUES[ParamType.REGION])
    assert editor.radius_spin.value() == pytest.approx(70.0)
    assert editor.center_spins[0].value() == pytest.approx(500.0)
    got = _committed(qtbot, editor)
    editor.radius_spin.setValue(120.0)
    assert got == [Region((0.5, 0.0, 0.2), 0.12)]


def test_joint_editor_in_degrees(qtbot: QtBot) -> None:
    editor = editor_for(ParamType.JOINTS)
    qtbot.addWidget(editor)
    assert len(editor.joint_spins) == 6
    joints = VALUES[ParamType.JOINTS]
    editor.set_value(joints)
    assert editor.joint_spins[1].value() == pytest.approx(math.degrees(-1.2), abs=1e-3)
    got = _committed(qtbot, editor)
    editor.joint_spins[0].setValue(90.0)
    assert got[-1].positions[0] == pytest.approx(math.pi / 2)
    assert got[-1].positions[1:] == joints.positions[1:]
    editor.set_value(JointConfig((0.0, 1.0)))
    assert len(editor.joint_spins) == 2


def test_concrete_types_expand_any() -> None:
    assert concrete_types(PortSpec("t", (ParamType.WAYPOINT, ParamType.POSE))) == [
        ParamType.WAYPOINT,
        ParamType.POSE,
    ]
    assert set(concrete_types(PortSpec("v", (ParamType.ANY,)))) == set(EDITOR_TYPES)
