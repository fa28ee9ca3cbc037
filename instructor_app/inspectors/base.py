"""The contract of a parameter editor and the spin box every numeric editor is made of.

An editor shows one value of one :class:`~engine.types.ParamType` and says when the user
has *finished* changing it (``value_committed``), never per keystroke: spin boxes do not
track the keyboard, text fields commit on Enter or focus out. ``set_value`` never emits, so
a view can refresh an editor from the document without echoing an edit back.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from PySide6.QtCore import QSize, Signal
from PySide6.QtWidgets import QDoubleSpinBox, QHBoxLayout, QWidget

from engine.operations import PortSpec
from engine.types import ParamType, Waypoint
from engine.units import DisplayUnit
from instructor_app.errors import InstructorError

__all__ = ["EditorContext", "ParamEditor", "UnitSpinBox", "InspectorError"]


class InspectorError(InstructorError):
    """An editor was asked for something it cannot show."""


@dataclass(frozen=True)
class EditorContext:
    """What some editors offer as choices: object library names and the plan's waypoints."""

    object_names: Sequence[str] = ()
    waypoints: Sequence[Waypoint] = field(default_factory=tuple)


class ParamEditor(QWidget):
    """Base of all editors: one value of ``param_type``, committed when the user is done.

    Signals:
        value_committed(object): the user finished an edit; the new value (SI units).
    """

    value_committed = Signal(object)
    param_type: ParamType = ParamType.ANY

    def __init__(self, port: PortSpec | None = None, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.port = port
        self._value: Any = None
        self._unset = False  # what it shows is not bound yet: choosing it binds it
        self._layout = QHBoxLayout(self)
        self._layout.setContentsMargins(0, 0, 0, 0)
        self._layout.setSpacing(2)

    def value(self) -> Any:
        """The value shown (None when the editor has nothing valid to offer)."""
        return self._value

    def set_value(self, value: Any) -> None:
        """Show ``value`` without emitting ``value_committed``."""
        self._value = value
        self._unset = False
        self._show(value)

    def show_unset(self, default: Any = None) -> None:
        """Show an unbound port: its default (when it has one), or what was shown; the user
        choosing or entering a value, even the one shown, binds it (``value_committed``).
        """
        if default is not None and default != self._value:
            self.set_value(default)
        self._unset = True

    def set_context(self, context: EditorContext) -> None:
        """New choices (objects, waypoints); editors without choices ignore it."""

    def _show(self, value: Any) -> None:
        raise NotImplementedError

    def _commit(self, value: Any) -> None:
        """Called by subclasses when the user changed the value."""
        if value is None or (value == self._value and not self._unset):
            return
        self._value = value
        self._unset = False
        self.value_committed.emit(value)


class UnitSpinBox(QDoubleSpinBox):
    """A spin box that shows a display unit and emits ``valueChanged`` only when done.

    Keyboard tracking is off: typing "123" changes the value once, on Enter or focus out,
    while the arrows and the wheel change it one step at a time.
    """

    def __init__(
        self,
        unit: DisplayUnit,
        minimum: float = -1e9,
        maximum: float = 1e9,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.unit = unit
        self.setKeyboardTracking(False)
        self.setDecimals(unit.decimals)
        self.setRange(minimum, maximum)
        if unit.suffix:
            self.setSuffix(" " + unit.suffix)
        self.setSingleStep(1.0 if unit.factor != 1.0 else 0.1)

    # The widest value a field sizes itself for (more still shows, scrolled in its field):
    # sized for its whole range (1e9), three fields of a pose would not fit the inspector.
    TYPICAL = 9999.99

    def _fitted(self, hint: QSize) -> QSize:
        """``hint`` (sized by Qt for the range's widest value) for the widest of a typical
        value and the value shown instead.
        """
        metrics = self.fontMetrics()

        def advance(value: float) -> int:
            text = self.prefix() + self.textFromValue(value) + self.suffix()
            return metrics.horizontalAdvance(text)

        widest = max(advance(self.minimum()), advance(self.maximum()))
        typical = max(self.minimum(), -self.TYPICAL)
        needed = max(advance(typical), advance(self.value()))
        return QSize(hint.width() - max(0, widest - needed), hint.height())

    def sizeHint(self) -> QSize:
        return self._fitted(super().sizeHint())

    def minimumSizeHint(self) -> QSize:
        return self._fitted(super().minimumSizeHint())

    def show_si(self, value: float) -> None:
        """Show an SI value converted, without signals."""
        self.blockSignals(True)
        self.setValue(self.unit.to_display(float(value)))
        self.blockSignals(False)

    def si_value(self) -> float:
        return self.unit.from_display(self.value())
