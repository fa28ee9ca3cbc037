"""Editors of single values: Number (with unit), Duration, Text, Bool, ObjectModel, Waypoint."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QSignalBlocker
from PySide6.QtWidgets import QCheckBox, QComboBox, QLineEdit, QWidget

from engine.operations import PortSpec
from engine.types import ObjectModel, ParamType, Waypoint
from engine.units import DisplayUnit, display_unit
from instructor_app.inspectors.base import EditorContext, ParamEditor, UnitSpinBox

__all__ = [
    "NumberEditor",
    "DurationEditor",
    "TextEditor",
    "ChoiceEditor",
    "BoolEditor",
    "ObjectModelEditor",
    "WaypointEditor",
]


class NumberEditor(ParamEditor):
    """A number; a port's SI unit is shown converted (m as mm, rad as degrees)."""

    param_type = ParamType.NUMBER
    minimum = -1e9

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.spin = UnitSpinBox(self._unit(port), minimum=self.minimum)
        self.spin.valueChanged.connect(lambda _v: self._commit(self.spin.si_value()))
        self._layout.addWidget(self.spin)
        self._value = 0.0

    def _unit(self, port: PortSpec | None) -> DisplayUnit:
        return display_unit(port.unit if port is not None else "")

    def _show(self, value: Any) -> None:
        self.spin.show_si(float(value or 0.0))


class DurationEditor(NumberEditor):
    """Seconds, not negative."""

    param_type = ParamType.DURATION
    minimum = 0.0

    def _unit(self, port: PortSpec | None) -> DisplayUnit:
        return DisplayUnit("s", 1.0, 3)


class TextEditor(ParamEditor):
    """Free text, committed on Enter or when the field loses focus."""

    param_type = ParamType.TEXT

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.line = QLineEdit()
        self.line.editingFinished.connect(lambda: self._commit(self.line.text()))
        self._layout.addWidget(self.line)
        self._value = ""

    def _show(self, value: Any) -> None:
        self.line.setText("" if value is None else str(value))


class ChoiceEditor(ParamEditor):
    """Text that must be one of a port's choices: a combo box."""

    param_type = ParamType.TEXT

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.combo = QComboBox()
        self.combo.addItems(list(port.choices) if port is not None else [])
        self.combo.activated.connect(lambda _i: self._commit(self.combo.currentText()))
        self._layout.addWidget(self.combo)
        self._value = self.combo.currentText()

    def _show(self, value: Any) -> None:
        text = "" if value is None else str(value)
        if self.combo.findText(text) < 0:
            # A value the manifest no longer offers (an old file): show it, validation says why.
            self.combo.addItem(text)
        self.combo.setCurrentIndex(self.combo.findText(text))


class BoolEditor(ParamEditor):
    """True or false."""

    param_type = ParamType.BOOL

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.check = QCheckBox()
        self.check.toggled.connect(self._commit)
        self._layout.addWidget(self.check)
        self._layout.addStretch(1)
        self._value = False

    def _show(self, value: Any) -> None:
        with QSignalBlocker(self.check):
            self.check.setChecked(bool(value))


class ObjectModelEditor(ParamEditor):
    """A name from the object library (an editable combo: a new model may not be there yet)."""

    param_type = ParamType.OBJECT

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.combo = QComboBox()
        self.combo.setEditable(True)
        self.combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        self.combo.activated.connect(lambda _i: self._commit_text())
        line = self.combo.lineEdit()
        if line is not None:
            line.editingFinished.connect(self._commit_text)
        self._layout.addWidget(self.combo)

    def _commit_text(self) -> None:
        name = self.combo.currentText().strip()
        self._commit(ObjectModel(name) if name else None)

    def set_context(self, context: EditorContext) -> None:
        current = self.combo.currentText()
        with QSignalBlocker(self.combo):
            self.combo.clear()
            self.combo.addItems(list(context.object_names))
            self.combo.setEditText(current)
        if self._value is None and context.object_names:
            self._value = ObjectModel(context.object_names[0])
            self._show(self._value)

    def _show(self, value: Any) -> None:
        with QSignalBlocker(self.combo):
            self.combo.setEditText(value.name if isinstance(value, ObjectModel) else "")


class WaypointEditor(ParamEditor):
    """One of the plan's waypoints; the binding stores the whole waypoint."""

    param_type = ParamType.WAYPOINT

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(port, parent)
        self.combo = QComboBox()
        self.combo.setPlaceholderText("choose a waypoint")
        self.combo.activated.connect(lambda i: self._commit(self.combo.itemData(i)))
        self._layout.addWidget(self.combo)

    def show_unset(self, default: Any = None) -> None:
        """An unbound waypoint port shows a blank asking for a choice, not the plan's first
        waypoint (which would read as chosen); choosing any, the first too, binds it.
        """
        super().show_unset(default)
        if default is None:
            with QSignalBlocker(self.combo):
                self.combo.setCurrentIndex(-1)

    def set_context(self, context: EditorContext) -> None:
        with QSignalBlocker(self.combo):
            self.combo.clear()
            for waypoint in context.waypoints:
                self.combo.addItem(f"{waypoint.name} ({waypoint.frame.value})", waypoint)
        if self._value is None and context.waypoints:
            self._value = context.waypoints[0]  # what "value" binds when chosen as the mode
        if self._unset:
            with QSignalBlocker(self.combo):
                self.combo.setCurrentIndex(-1)
        else:
            self._show(self._value)

    def _show(self, value: Any) -> None:
        if not isinstance(value, Waypoint):
            self.combo.setCurrentIndex(-1)
            return
        names = [self.combo.itemData(i).name for i in range(self.combo.count())]
        if value.name in names:
            index = names.index(value.name)
        else:
            # A waypoint bound before it left the plan's list: still shown, still kept.
            self.combo.addItem(f"{value.name} (not in the plan)", value)
            index = self.combo.count() - 1
        with QSignalBlocker(self.combo):
            self.combo.setCurrentIndex(index)
