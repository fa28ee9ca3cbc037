"""The Move panel, as on PolyScope's Move tab: where the tool and the joints are, jog
arrows, a speed slider and a Freedrive button.

The tool pose is shown in the world frame (origin at the robot's base, z up) in mm and
degrees (roll, pitch, yaw about fixed axes, as the inspector shows poses), the joints in
degrees. Arrows jog the tool in the base or the tool frame, and the joints one by one: by
the chosen step per click, or while held (the arm moves while the button is down and stops
when it is let go). On a real arm Freedrive is held too, as on the pendant: the arm can be
guided by hand while it is down. On a cell whose freedrive takes a dragged pose (the
simulated one) the hand is the mouse, which cannot hold the button and drag the tool in the
3D scene at once: there Freedrive is a toggle (a click turns it on and the button stays
down; the next click, Esc, a run starting or the cell changing turn it off), and a line
under the button says how to drag.
All commands go through :class:`instructor_app.runtime.teach.RobotTeacher`.
"""

from __future__ import annotations

import math

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeySequence, QShortcut
from PySide6.QtWidgets import (
    QComboBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from engine.units import quaternion_to_rpy
from instructor_app.runtime.teach import ArmState, RobotTeacher

__all__ = [
    "DRAG_HINT",
    "DRAG_HINT_OFF",
    "FREEDRIVE_HELD",
    "FREEDRIVE_ON",
    "FREEDRIVE_TOGGLE",
    "FREEDRIVE_TOGGLE_ON",
    "MovePanel",
    "STEPS",
    "HOLD",
    "JOINT_NAMES",
]

HOLD = "while held"
# The Freedrive button's words: held (a real arm) and toggled (the simulated cell).
FREEDRIVE_HELD = "Freedrive (hold)"
FREEDRIVE_ON = "Freedrive: ON"
FREEDRIVE_TOGGLE = "Freedrive (click to turn on)"
FREEDRIVE_TOGGLE_ON = "Freedrive ON: drag the tool in the 3D scene"
# The line under it on the simulated cell: both ways to drag the tool.
DRAG_HINT_OFF = "Click Freedrive, then drag the tool in the 3D scene; Shift+drag works any time"
DRAG_HINT = "Drag the tool in the 3D scene; Shift+drag works any time. Click again or Esc: off"
# (label, metres, radians): the step of one click, for moves and for turns.
STEPS: tuple[tuple[str, float, float], ...] = (
    (HOLD, 0.0, 0.0),
    ("0.1 mm / 0.1°", 0.0001, math.radians(0.1)),
    ("1 mm / 1°", 0.001, math.radians(1.0)),
    ("5 mm / 5°", 0.005, math.radians(5.0)),
    ("10 mm / 10°", 0.010, math.radians(10.0)),
    ("50 mm / 15°", 0.050, math.radians(15.0)),
)
JOINT_NAMES = ("Base", "Shoulder", "Elbow", "Wrist 1", "Wrist 2", "Wrist 3")
_POSE_LABELS = ("X", "Y", "Z", "Roll", "Pitch", "Yaw")
_FRAMES = (("Base", "base"), ("Tool", "tool"))
_MINUS = "\u2212"  # a real minus sign on the buttons


def _number(value: float, decimals: int) -> str:
    """``value`` rounded for display, without a "-0.0"."""
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


class MovePanel(QWidget):
    """Live pose and joints, jog arrows, speed and Freedrive.

    Args:
        teacher: sends the commands to the robot off the GUI thread.
    """

    def __init__(self, teacher: RobotTeacher, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.teacher = teacher
        self.jog_buttons: dict[str, QPushButton] = {}
        self.joint_buttons: dict[tuple[int, int], QPushButton] = {}
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(self._build_pose())
        layout.addWidget(self._build_jog())
        layout.addWidget(self._build_joints())
        layout.addLayout(self._build_speed())
        self.freedrive_button = QPushButton(FREEDRIVE_HELD)
        self.freedrive_button.setMinimumWidth(80)
        self.freedrive_button.setObjectName("FreedriveButton")
        self.freedrive_button.setToolTip(
            "Hold down to guide the arm by hand; let go and the arm stays where it is"
        )
        self.freedrive_button.setMinimumHeight(36)
        # Held on a real arm (pressed/released), a toggle on the simulated cell (toggled).
        self.freedrive_button.pressed.connect(self._freedrive_pressed)
        self.freedrive_button.released.connect(self._freedrive_released)
        self.freedrive_button.toggled.connect(self._freedrive_toggled)
        self._freedrive_escape = QShortcut(QKeySequence(Qt.Key.Key_Escape), self)
        self._freedrive_escape.setContext(Qt.ShortcutContext.WindowShortcut)
        self._freedrive_escape.setEnabled(False)  # only while toggled on
        self._freedrive_escape.activated.connect(self.freedrive_off)
        layout.addWidget(self.freedrive_button)
        self.freedrive_hint = QLabel("")
        self.freedrive_hint.setObjectName("FreedriveHint")
        self.freedrive_hint.setWordWrap(True)
        layout.addWidget(self.freedrive_hint)
        self.status_label = QLabel("")
        self.status_label.setWordWrap(True)
        layout.addWidget(self.status_label)
        layout.addStretch(1)
        teacher.state_changed.connect(self.show_state)
        teacher.availability_changed.connect(self._update_enabled)
        teacher.message.connect(self.status_label.setText)
        teacher.freedrive_left.connect(lambda: self._set_toggled(False))
        self.show_state(teacher.state)
        self._update_enabled()

    # ------------------------------------------------------------------ layout

    def _build_pose(self) -> QGroupBox:
        box = QGroupBox("Tool (world frame)")
        grid = QGridLayout(box)
        self.pose_labels: list[QLabel] = []
        grid.setHorizontalSpacing(6)
        for index, name in enumerate(_POSE_LABELS):
            value = QLabel("—")
            value.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            value.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
            row, column = index % 3, 2 * (index // 3)
            grid.addWidget(QLabel(name), row, column)
            grid.addWidget(value, row, column + 1)
            self.pose_labels.append(value)
        grid.setColumnStretch(1, 1)
        grid.setColumnStretch(3, 1)
        return box

    def _build_jog(self) -> QGroupBox:
        box = QGroupBox("Jog the tool")
        outer = QVBoxLayout(box)
        options = QGridLayout()
        self.frame_combo = QComboBox()
        for text, frame in _FRAMES:
            self.frame_combo.addItem(text, frame)
        self.frame_combo.setToolTip(
            "Base: along the world axes (origin at the robot's base, z up); "
            "Tool: along the tool's own axes (z points out of the tool)"
        )
        self.step_combo = QComboBox()
        self.step_combo.addItems([label for label, _, _ in STEPS])
        self.step_combo.setToolTip("How far one click moves; 'while held' moves until let go")
        options.addWidget(QLabel("Frame"), 0, 0)
        options.addWidget(self.frame_combo, 0, 1)
        options.addWidget(QLabel("Step"), 1, 0)
        options.addWidget(self.step_combo, 1, 1)
        options.setColumnStretch(1, 1)
        outer.addLayout(options)
        grid = QGridLayout()
        for row, letter in enumerate("xyz"):
            for column, axis in ((0, letter), (2, f"r{letter}")):
                for offset, sign in ((0, -1), (1, 1)):
                    grid.addWidget(self._jog_button(axis, sign), row, column + offset)
        outer.addLayout(grid)
        return box

    def _jog_button(self, axis: str, sign: int) -> QPushButton:
        text = f"{axis.upper() if len(axis) == 1 else 'R' + axis[1]}{_MINUS if sign < 0 else '+'}"
        button = QPushButton(text)
        button.setMinimumWidth(40)
        button.setObjectName(f"jog_{axis}{'-' if sign < 0 else '+'}")
        button.setAutoRepeat(False)
        button.pressed.connect(lambda: self._jog_pressed(axis, sign))
        button.released.connect(self._released)
        self.jog_buttons[f"{axis}{'-' if sign < 0 else '+'}"] = button
        return button

    def _build_joints(self) -> QGroupBox:
        box = QGroupBox("Joints")
        grid = QGridLayout(box)
        self.joint_labels: list[QLabel] = []
        for joint, name in enumerate(JOINT_NAMES):
            value = QLabel("—")
            value.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            grid.addWidget(QLabel(name), joint, 0)
            grid.addWidget(self._joint_button(joint, -1), joint, 1)
            grid.addWidget(value, joint, 2)
            grid.addWidget(self._joint_button(joint, 1), joint, 3)
            self.joint_labels.append(value)
        return box

    def _joint_button(self, joint: int, sign: int) -> QPushButton:
        button = QPushButton(_MINUS if sign < 0 else "+")
        button.setObjectName(f"joint{joint + 1}{'-' if sign < 0 else '+'}")
        button.setMaximumWidth(36)
        button.pressed.connect(lambda: self._joint_pressed(joint, sign))
        button.released.connect(self._released)
        self.joint_buttons[(joint, sign)] = button
        return button

    def _build_speed(self) -> QHBoxLayout:
        row = QHBoxLayout()
        self.speed_slider = QSlider(Qt.Orientation.Horizontal)
        self.speed_slider.setRange(1, 100)
        self.speed_slider.setValue(round(self.teacher.speed_fraction * 100))
        self.speed_slider.setToolTip("Speed of jogs and of Move here (which runs at a quarter)")
        self.speed_label = QLabel()
        self.speed_slider.valueChanged.connect(self._speed_changed)
        self._speed_changed(self.speed_slider.value())
        row.addWidget(QLabel("Speed"))
        row.addWidget(self.speed_slider, 1)
        row.addWidget(self.speed_label)
        return row

    # ------------------------------------------------------------------ state

    @property
    def frame(self) -> str:
        return str(self.frame_combo.currentData())

    def step(self) -> tuple[float, float]:
        """(metres, radians) of one click; (0, 0) when jogging while held."""
        _, metres, radians = STEPS[self.step_combo.currentIndex()]
        return metres, radians

    def show_state(self, state: object) -> None:
        """Show an :class:`ArmState` (None: dashes)."""
        if not isinstance(state, ArmState):
            for label in (*self.pose_labels, *self.joint_labels):
                label.setText("—")
            return
        values = [v * 1000 for v in state.tcp.position]
        values += [math.degrees(a) for a in quaternion_to_rpy(state.tcp.orientation)]
        for label, value, unit in zip(
            self.pose_labels, values, ("mm",) * 3 + ("°",) * 3, strict=True
        ):
            label.setText(f"{_number(value, 1)} {unit}")
        for label, angle in zip(self.joint_labels, state.joints, strict=False):
            label.setText(f"{_number(math.degrees(angle), 2)} °")
        self._show_freedrive(state.freedrive)

    def _show_freedrive(self, on: bool) -> None:
        if self.freedrive_button.isCheckable():
            self.freedrive_button.setText(FREEDRIVE_TOGGLE_ON if on else FREEDRIVE_TOGGLE)
            self.freedrive_hint.setText(DRAG_HINT if on else DRAG_HINT_OFF)
        else:
            self.freedrive_button.setText(FREEDRIVE_ON if on else FREEDRIVE_HELD)
            self.freedrive_hint.setText("")

    def _drag_guided(self) -> bool:
        """The cell's freedrive follows a pose dragged in the 3D scene (no hand on a real arm
        there: the simulated cell's).
        """
        return hasattr(self.teacher.interface("freedrive"), "freedrive_drag_to")

    def _update_enabled(self) -> None:
        reason = self.teacher.unavailable_reason("arm")
        buttons = [*self.jog_buttons.values(), *self.joint_buttons.values()]
        for button in buttons:
            button.setEnabled(not reason)
        drive_reason = self.teacher.unavailable_reason("freedrive")
        toggle = self._drag_guided()
        if drive_reason or not toggle:
            # A run starting or another cell: the toggle is let go without a command (the
            # teacher turns freedrive off before a run, and a new cell starts with it off).
            self._set_toggled(False)
        self.freedrive_button.setCheckable(toggle)
        self.freedrive_button.setEnabled(not drive_reason)
        hold = "Hold down to guide the arm by hand"
        if toggle:
            hold = (
                "Click to turn on, then drag the tool in the 3D scene: the arm follows; "
                "click again (or Esc) to turn off"
            )
        self.freedrive_button.setToolTip(drive_reason.capitalize() if drive_reason else hold)
        state = self.teacher.state
        self._show_freedrive(isinstance(state, ArmState) and state.freedrive)
        self.status_label.setText(f"Cannot move the robot: {reason}." if reason else "")

    # ------------------------------------------------------------------ user actions

    def _speed_changed(self, value: int) -> None:
        self.teacher.speed_fraction = value / 100
        self.speed_label.setText(f"{value:3d} %")

    def freedrive_off(self) -> None:
        """Turn a toggled Freedrive off (the next click, or Esc)."""
        if self.freedrive_button.isChecked():
            self.freedrive_button.setChecked(False)  # toggled(False): the teacher lets go

    def _freedrive_pressed(self) -> None:
        if not self.freedrive_button.isCheckable():
            self.teacher.press_freedrive()

    def _freedrive_released(self) -> None:
        if not self.freedrive_button.isCheckable():
            self.teacher.release_freedrive()

    def _freedrive_toggled(self, on: bool) -> None:
        self._freedrive_escape.setEnabled(on)
        if not self.freedrive_button.isCheckable():
            return
        if not on:
            self.teacher.release_freedrive()
        elif not self.teacher.press_freedrive():
            self._set_toggled(False)  # refused (the teacher said why)

    def _set_toggled(self, on: bool) -> None:
        """Show the toggle on or off without sending a command."""
        blocked = self.freedrive_button.blockSignals(True)
        self.freedrive_button.setChecked(on)
        self.freedrive_button.blockSignals(blocked)
        self._freedrive_escape.setEnabled(on)

    def _jog_pressed(self, axis: str, sign: int) -> None:
        metres, radians = self.step()
        if metres == 0.0:
            self.teacher.hold_jog(self.frame, axis, sign)
        else:
            amount = radians if axis.startswith("r") else metres
            self.teacher.jog_step(self.frame, axis, sign * amount)

    def _joint_pressed(self, joint: int, sign: int) -> None:
        _, radians = self.step()
        if radians == 0.0:
            self.teacher.hold_joint(joint, sign)
        else:
            self.teacher.jog_joint_step(joint, sign * radians)

    def _released(self) -> None:
        if self.step() == (0.0, 0.0):
            self.teacher.release()
