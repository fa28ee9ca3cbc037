"""Rows of the inspector: one per operation port, one per logic-node setting.

A row turns what the user finished doing into one new binding (or setting value) and emits
it; it never touches the document. ``load`` shows the document's state again without
emitting, in place, so the field being edited keeps its focus.
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QStringListModel, Qt, Signal
from PySide6.QtWidgets import (
    QComboBox,
    QCompleter,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QSpinBox,
    QStackedWidget,
    QVBoxLayout,
    QWidget,
)

from engine.kinds import ConfigField
from engine.operations import Direction, PortSpec
from engine.spec import Binding
from engine.types import ParamType
from instructor_app.inspectors.base import EditorContext, ParamEditor
from instructor_app.inspectors.factory import concrete_types, editor_for
from instructor_app.inspectors.units import display_unit, format_value

__all__ = ["PortRow", "ConfigRow", "MODE_UNSET", "MODE_VALUE", "MODE_REFERENCE"]

MODE_UNSET, MODE_VALUE, MODE_REFERENCE = 0, 1, 2


def _name_field(model: QStringListModel) -> QLineEdit:
    line = QLineEdit()
    completer = QCompleter(model, line)
    completer.setCaseSensitivity(Qt.CaseSensitivity.CaseInsensitive)
    completer.setFilterMode(Qt.MatchFlag.MatchContains)
    line.setCompleter(completer)
    line.setPlaceholderText("parameter name, e.g. CUP_POSE")
    return line


class PortRow(QWidget):
    """One port of an operation node.

    Inputs: a mode switch (unset / value / parameter), for values the editor of the chosen
    type, for parameters a name with completion. Outputs: the name the result is stored
    under.

    Signals:
        binding_committed(object): the new Binding, or None to unbind.
    """

    binding_committed = Signal(object)

    def __init__(
        self,
        port: PortSpec,
        names: QStringListModel,
        context: EditorContext,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.port = port
        self._context = context
        self.types = concrete_types(port) or [ParamType.TEXT]
        self.ref_field = _name_field(names)
        self.ref_field.editingFinished.connect(self._ref_finished)
        self.editor: ParamEditor | None = None
        self.mode_combo = QComboBox()
        self.type_combo = QComboBox()
        self.stack = QStackedWidget()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        if port.direction is Direction.OUT:
            layout.addWidget(self.ref_field)
            return
        self._build_input(layout)

    def _build_input(self, layout: QVBoxLayout) -> None:
        unset = "not set" if self.port.required else f"default: {format_value(self.port.default)}"
        self.mode_combo.addItems([unset, "value", "parameter"])
        self.mode_combo.activated.connect(self._mode_chosen)
        self.type_combo.addItems([t.value for t in self.types])
        self.type_combo.activated.connect(self._type_chosen)
        self.type_combo.setVisible(len(self.types) > 1)
        top = QHBoxLayout()
        top.addWidget(self.mode_combo)
        top.addWidget(self.type_combo)
        layout.addLayout(top)
        self.stack.addWidget(QLabel())  # MODE_UNSET: nothing to edit
        self.stack.addWidget(QWidget())  # MODE_VALUE: replaced by the editor
        self.stack.addWidget(self.ref_field)
        layout.addWidget(self.stack)
        self._set_editor(self.types[0])
        self._show_mode(MODE_UNSET)

    # ------------------------------------------------------------------ state

    @property
    def mode(self) -> int:
        return self.mode_combo.currentIndex()

    @property
    def value_type(self) -> ParamType:
        return self.types[max(0, self.type_combo.currentIndex())]

    def set_context(self, context: EditorContext) -> None:
        self._context = context
        if self.editor is not None:
            self.editor.set_context(context)

    def load(self, binding: Binding | None) -> None:
        """Show a binding (None: unbound) without emitting."""
        if self.port.direction is Direction.OUT:
            self._set_ref_text(binding.ref if binding is not None and binding.ref else "")
            return
        if binding is None:
            self._show_mode(MODE_UNSET)
        elif binding.is_ref:
            self._set_ref_text(binding.ref or "")
            self._show_mode(MODE_REFERENCE)
        else:
            ptype = ParamType(binding.type) if binding.type is not None else self.types[0]
            if ptype not in self.types:
                self.types.append(ptype)
                self.type_combo.addItem(ptype.value)
            if ptype is not self.value_type or self.editor is None:
                self.type_combo.setCurrentIndex(self.types.index(ptype))
                self._set_editor(ptype)
            assert self.editor is not None
            self.editor.set_value(binding.value)
            self._show_mode(MODE_VALUE)

    def _set_ref_text(self, text: str) -> None:
        if self.ref_field.text() != text:
            self.ref_field.setText(text)

    def _show_mode(self, mode: int) -> None:
        self.mode_combo.setCurrentIndex(mode)
        self.stack.setCurrentIndex(mode)
        self.type_combo.setVisible(mode == MODE_VALUE and len(self.types) > 1)

    def _set_editor(self, ptype: ParamType) -> None:
        old = self.stack.widget(MODE_VALUE)
        self.editor = editor_for(ptype, self.port, self._context)
        self.editor.value_committed.connect(self._value_committed)
        self.stack.insertWidget(MODE_VALUE, self.editor)
        if old is not None:
            self.stack.removeWidget(old)
            old.deleteLater()  # it may be the sender of the signal being handled

    # ------------------------------------------------------------------ user actions

    def _mode_chosen(self, mode: int) -> None:
        self._show_mode(mode)
        if mode == MODE_UNSET:
            self.binding_committed.emit(None)
        elif mode == MODE_VALUE:
            self._emit_fixed()
        else:
            self.ref_field.setFocus()
            self._ref_finished()

    def _type_chosen(self, index: int) -> None:
        self._set_editor(self.types[index])
        self._emit_fixed()

    def _emit_fixed(self) -> None:
        if self.editor is not None and self.editor.value() is not None:
            self.binding_committed.emit(Binding.fixed(self.editor.value(), self.value_type))

    def _value_committed(self, value: Any) -> None:
        self.binding_committed.emit(Binding.fixed(value, self.value_type))

    def _ref_finished(self) -> None:
        name = self.ref_field.text().strip()
        if name:
            self.binding_committed.emit(Binding.reference(name))
        elif self.port.direction is Direction.OUT:
            self.binding_committed.emit(None)


class ConfigRow(QWidget):
    """One setting of a logic node (count, seconds, parallel policy).

    Signals:
        value_committed(object): the new value, or None to remove an optional setting.
    """

    value_committed = Signal(object)

    def __init__(self, field: ConfigField, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.field = field
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.widget: QWidget = self._make_widget()
        layout.addWidget(self.widget)
        self.setToolTip(field.doc)

    def _make_widget(self) -> QWidget:
        optional = not self.field.required
        if self.field.kind == "count":
            spin = QSpinBox()
            spin.setRange(0 if optional else 1, 1_000_000)
            spin.setSpecialValueText("off" if optional else "")
            spin.setKeyboardTracking(False)
            spin.valueChanged.connect(lambda v: self.value_committed.emit(v or None))
            return spin
        if self.field.kind in ("seconds", "wait_seconds"):
            spin_f = QDoubleSpinBox()
            minimum = 0.0 if optional or self.field.kind == "wait_seconds" else 0.001
            spin_f.setRange(minimum, 1e6)
            spin_f.setDecimals(3)
            spin_f.setSuffix(" " + display_unit("s").suffix)
            spin_f.setSpecialValueText("off" if optional else "")
            spin_f.setKeyboardTracking(False)
            spin_f.valueChanged.connect(
                lambda v: self.value_committed.emit(v if v or not optional else None)
            )
            return spin_f
        combo = QComboBox()
        combo.setEditable(True)
        combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        combo.addItems(["all", "any"] if self.field.kind == "policy_success" else ["any"])
        combo.setToolTip("a word, or a number of children")
        combo.activated.connect(lambda _i: self._policy_finished())
        line = combo.lineEdit()
        if line is not None:
            line.editingFinished.connect(self._policy_finished)
        return combo

    def _policy_finished(self) -> None:
        assert isinstance(self.widget, QComboBox)
        text = self.widget.currentText().strip().lower()
        if text.isdigit() and int(text) >= 1:
            self.value_committed.emit(int(text))
        elif text in ("all", "any"):
            self.value_committed.emit(text)
        # Anything else is not a policy: the next load shows the stored one again.

    def load(self, value: Any) -> None:
        """Show the stored value (None: the default) without emitting."""
        shown = self.field.default if value is None else value
        self.widget.blockSignals(True)
        if isinstance(self.widget, QSpinBox):
            self.widget.setValue(int(shown or 0))
        elif isinstance(self.widget, QDoubleSpinBox):
            self.widget.setValue(float(shown or 0.0))
        elif isinstance(self.widget, QComboBox):
            self.widget.setEditText(str(shown))
        self.widget.blockSignals(False)
