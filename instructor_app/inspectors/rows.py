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
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QStackedWidget,
    QVBoxLayout,
    QWidget,
)

from engine.operations import Direction, PortSpec
from engine.spec import Binding
from engine.types import ParamType
from engine.units import format_value
from instructor_app.inspectors.base import EditorContext, ParamEditor
from instructor_app.inspectors.factory import concrete_types, editor_for

__all__ = ["PortRow", "MODE_UNSET", "MODE_VALUE", "MODE_REFERENCE"]

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

    Inputs: a mode switch (unset / value / parameter), for values (and while unset: a value
    chosen or typed there binds it, no need to switch to "value" first) the editor of the
    chosen type, for parameters a name with completion that lists the offered names first (the
    outputs of this type written before the node, nearest first: ``set_offers``); choosing
    "parameter" with no name yet binds the first offer. Outputs: the name the result is
    stored under.

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
        self._names = names
        self._offers: list[str] = []
        if port.direction is Direction.OUT:
            self.ref_field = _name_field(names)
        else:  # its own list: the offers first, then the plan's other names
            self._choices = QStringListModel(self)
            self.ref_field = _name_field(self._choices)
            names.modelReset.connect(self._fill_choices)
            self._fill_choices()
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
        self.stack.addWidget(QLabel())  # MODE_UNSET: shows the editor (see _show_mode)
        self.stack.addWidget(QWidget())  # MODE_VALUE: replaced by the editor
        self.stack.addWidget(self.ref_field)
        layout.addWidget(self.stack)
        self._set_editor(self.types[0])
        assert self.editor is not None
        self.editor.show_unset(self._default_shown())
        self._show_mode(MODE_UNSET)

    # ------------------------------------------------------------------ state

    @property
    def mode(self) -> int:
        return self.mode_combo.currentIndex()

    @property
    def value_type(self) -> ParamType:
        return self.types[max(0, self.type_combo.currentIndex())]

    @property
    def offers(self) -> list[str]:
        """Names offered first for a parameter of this input, the nearest output first."""
        return list(self._offers)

    def set_offers(self, names: list[str]) -> None:
        if names != self._offers:
            self._offers = list(names)
            self._fill_choices()

    def reference_choices(self) -> list[str]:
        """The names the parameter field's completion lists, in order."""
        return self.ref_field.completer().model().stringList()  # type: ignore[attr-defined]

    def _fill_choices(self) -> None:
        if self.port.direction is Direction.OUT:
            return
        rest = [n for n in self._names.stringList() if n not in self._offers]
        choices = [*self._offers, *rest]
        if choices != self._choices.stringList():
            self._choices.setStringList(choices)

    def set_context(self, context: EditorContext) -> None:
        self._context = context
        if self.editor is not None:
            self.editor.set_context(context)
            if self.mode == MODE_UNSET:
                self.editor.show_unset(self._default_shown())

    def load(self, binding: Binding | None) -> None:
        """Show a binding (None: unbound) without emitting."""
        if self.port.direction is Direction.OUT:
            self._set_ref_text(binding.ref if binding is not None and binding.ref else "")
            return
        if binding is None:
            if self.editor is not None:
                self.editor.show_unset(self._default_shown())
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

    def _default_shown(self) -> Any:
        """The port's default, for the editor of its first type (the default's own)."""
        return self.port.default if self.value_type is self.types[0] else None

    def _set_ref_text(self, text: str) -> None:
        if self.ref_field.text() != text:
            self.ref_field.setText(text)

    def _show_mode(self, mode: int) -> None:
        self.mode_combo.setCurrentIndex(mode)
        self.stack.setCurrentIndex(MODE_VALUE if mode == MODE_UNSET else mode)
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
            if not self.ref_field.text().strip() and self._offers:
                self.ref_field.setText(self._offers[0])  # the nearest output of this type
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
