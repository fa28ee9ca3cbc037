"""Editors of compound values: Pose, Region and JointConfig, as rows of unit spin boxes.

Each keeps the exact stored value until the user changes a field, and then recomputes only
the part that field belongs to: editing x of a pose keeps its quaternion bit for bit (a
round trip through degrees would not).
"""

from __future__ import annotations

import math
from typing import Any

from PySide6.QtWidgets import QAbstractSpinBox, QGridLayout, QLabel, QWidget

from engine.operations import PortSpec
from engine.types import JointConfig, ParamType, Pose, Region
from engine.units import display_unit, quaternion_to_rpy, rpy_to_quaternion
from instructor_app.inspectors.base import ParamEditor, UnitSpinBox

__all__ = ["PoseEditor", "RegionEditor", "JointConfigEditor"]

_MM = display_unit("m")
_DEG = display_unit("rad")
DEFAULT_JOINT_COUNT = 6


def _grid(owner: ParamEditor) -> QGridLayout:
    holder = QWidget()
    grid = QGridLayout(holder)
    grid.setContentsMargins(0, 0, 0, 0)
    grid.setHorizontalSpacing(2)
    grid.setVerticalSpacing(2)
    owner._layout.addWidget(holder)
    return grid


def _kept(spins: list[UnitSpinBox], stored: tuple[float, ...]) -> list[float]:
    """The SI values of the spins; a field whose display still matches its stored value
    keeps the stored value exactly (the display is rounded).
    """
    values = []
    for spin, value in zip(spins, stored, strict=False):
        untouched = math.isclose(
            spin.value(), spin.unit.to_display(value), abs_tol=0.51 * 10 ** -spin.decimals()
        )
        values.append(value if untouched else spin.si_value())
    return values + [spin.si_value() for spin in spins[len(values) :]]


def _spins(
    grid: QGridLayout, row: int, labels: str, unit: Any, on_change: Any
) -> list[UnitSpinBox]:
    # Each name above its field, and no arrow buttons (the arrow keys and the wheel still
    # step): three fields side by side fit the inspector of a 1366 px wide window.
    spins = []
    for column, label in enumerate(labels.split()):
        spin = UnitSpinBox(unit)
        spin.setButtonSymbols(QAbstractSpinBox.ButtonSymbols.NoButtons)
        spin.valueChanged.connect(lambda _v: on_change())
        grid.addWidget(QLabel(label), 2 * row, column)
        grid.addWidget(spin, 2 * row + 1, column)
        spins.append(spin)
    return spins


class PoseEditor(ParamEditor):
    """A pose: x, y, z in mm and roll, pitch, yaw in degrees (fixed axes)."""

    param_type = ParamType.POSE

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        grid = _grid(self)
        self.position_spins = _spins(grid, 0, "x y z", _MM, self._position_edited)
        self.angle_spins = _spins(grid, 1, "roll pitch yaw", _DEG, self._angles_edited)
        self._value = Pose()

    def _show(self, value: Any) -> None:
        pose = value if isinstance(value, Pose) else Pose()
        for spin, v in zip(self.position_spins, pose.position, strict=True):
            spin.show_si(v)
        for spin, a in zip(self.angle_spins, quaternion_to_rpy(pose.orientation), strict=True):
            spin.show_si(a)

    def _current(self) -> Pose:
        return self._value if isinstance(self._value, Pose) else Pose()

    def _position_edited(self) -> None:
        position = tuple(_kept(self.position_spins, self._current().position))
        self._commit(Pose.of(position, self._current().orientation))

    def _angles_edited(self) -> None:
        stored = quaternion_to_rpy(self._current().orientation)
        roll, pitch, yaw = _kept(self.angle_spins, stored)
        self._commit(Pose(self._current().position, rpy_to_quaternion(roll, pitch, yaw)))


class RegionEditor(ParamEditor):
    """A sphere: centre x, y, z in mm and radius in mm (above 0)."""

    param_type = ParamType.REGION
    DEFAULT = Region((0.0, 0.0, 0.0), 0.1)

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        grid = _grid(self)
        self.center_spins = _spins(grid, 0, "x y z", _MM, self._edited)
        self.radius_spin = _spins(grid, 1, "radius", _MM, self._edited)[0]
        self.radius_spin.setMinimum(0.01)
        self._value = self.DEFAULT

    def _show(self, value: Any) -> None:
        region = value if isinstance(value, Region) else self.DEFAULT
        for spin, v in zip(self.center_spins, region.center, strict=True):
            spin.show_si(v)
        self.radius_spin.show_si(region.radius)

    def _edited(self) -> None:
        current = self._value if isinstance(self._value, Region) else self.DEFAULT
        values = _kept([*self.center_spins, self.radius_spin], (*current.center, current.radius))
        self._commit(Region((values[0], values[1], values[2]), values[3]))


class JointConfigEditor(ParamEditor):
    """Joint angles in degrees, base to wrist (six for the UR5)."""

    param_type = ParamType.JOINTS

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self._grid = _grid(self)
        self.joint_spins: list[UnitSpinBox] = []
        self._make_spins(DEFAULT_JOINT_COUNT)
        self._value = JointConfig((0.0,) * DEFAULT_JOINT_COUNT)

    def _make_spins(self, count: int) -> None:
        for spin in self.joint_spins:
            spin.deleteLater()
        self.joint_spins = []
        for index in range(count):
            spin = UnitSpinBox(_DEG, minimum=-720.0, maximum=720.0)
            spin.valueChanged.connect(lambda _v: self._edited())
            self._grid.addWidget(spin, index // 3, index % 3)
            spin.setToolTip(f"joint {index + 1}")
            self.joint_spins.append(spin)

    def _show(self, value: Any) -> None:
        joints = (
            value if isinstance(value, JointConfig) else JointConfig((0.0,) * len(self.joint_spins))
        )
        if len(joints.positions) != len(self.joint_spins):
            self._make_spins(len(joints.positions))
        for spin, v in zip(self.joint_spins, joints.positions, strict=True):
            spin.show_si(v)

    def _edited(self) -> None:
        current = self._value.positions if isinstance(self._value, JointConfig) else ()
        self._commit(JointConfig(tuple(_kept(self.joint_spins, current))))
