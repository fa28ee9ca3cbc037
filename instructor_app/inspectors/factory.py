"""Parameter type -> editor widget: one table, as NodeGraphQt's property widget factory.

A new parameter type needs one editor class and one row in :data:`EDITOR_TYPES`; the
inspector asks :func:`editor_for` and never names an editor class itself.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from PySide6.QtWidgets import QWidget

from engine.operations import PortSpec
from engine.types import JointConfig, ObjectModel, ParamType, Pose, check_value
from instructor_app.inspectors.base import EditorContext, ParamEditor
from instructor_app.inspectors.editors import (
    BoolEditor,
    ChoiceEditor,
    DurationEditor,
    NumberEditor,
    ObjectModelEditor,
    TextEditor,
    WaypointEditor,
)
from instructor_app.inspectors.geometry import (
    DEFAULT_JOINT_COUNT,
    JointConfigEditor,
    PoseEditor,
    RegionEditor,
)

__all__ = ["EDITOR_TYPES", "editor_for", "default_value", "concrete_types"]

EDITOR_TYPES: dict[ParamType, type[ParamEditor]] = {
    ParamType.NUMBER: NumberEditor,
    ParamType.DURATION: DurationEditor,
    ParamType.TEXT: TextEditor,
    ParamType.BOOL: BoolEditor,
    ParamType.OBJECT: ObjectModelEditor,
    ParamType.WAYPOINT: WaypointEditor,
    ParamType.POSE: PoseEditor,
    ParamType.REGION: RegionEditor,
    ParamType.JOINTS: JointConfigEditor,
}


def concrete_types(port: PortSpec) -> list[ParamType]:
    """The types a fixed value of the port can have, in the port's order (Any: all of them)."""
    found: list[ParamType] = []
    for ptype in port.types:
        options = list(EDITOR_TYPES) if ptype is ParamType.ANY else [ptype]
        found += [t for t in options if t not in found]
    return found


def default_value(ptype: ParamType, port: PortSpec | None, context: EditorContext) -> Any:
    """What a fresh editor of ``ptype`` shows: the port's default if it fits, else a neutral
    value (None where there is nothing to offer, e.g. no waypoints in the plan).
    """
    if port is not None and port.default is not None and check_value(ptype, port.default):
        return port.default
    if ptype is ParamType.TEXT and port is not None and port.choices:
        return port.choices[0]
    neutral: dict[ParamType, Any] = {
        ParamType.NUMBER: 0.0,
        ParamType.DURATION: 1.0,
        ParamType.TEXT: "",
        ParamType.BOOL: False,
        ParamType.POSE: Pose(),
        ParamType.REGION: RegionEditor.DEFAULT,
        ParamType.JOINTS: JointConfig((0.0,) * DEFAULT_JOINT_COUNT),
        ParamType.OBJECT: ObjectModel(context.object_names[0]) if context.object_names else None,
        ParamType.WAYPOINT: context.waypoints[0] if context.waypoints else None,
    }
    return neutral.get(ptype)


def editor_for(
    param_type: ParamType,
    port: PortSpec | None = None,
    context: EditorContext | None = None,
    parent: QWidget | None = None,
) -> ParamEditor:
    """A new editor for a value of ``param_type`` (for ``port``, whose unit and choices it
    uses), showing the default value. Unknown types get a text field.
    """
    ptype = ParamType(param_type)
    if ptype is ParamType.TEXT and port is not None and port.choices:
        cls: type[ParamEditor] = ChoiceEditor
    else:
        cls = EDITOR_TYPES.get(ptype, TextEditor)
    editor = cls(port, parent)
    context = context or EditorContext()
    editor.set_context(context)
    editor.set_value(default_value(ptype, port, context))
    return editor


def type_names(types: Sequence[ParamType]) -> str:
    """The types as the user reads them, e.g. "Pose or Waypoint"."""
    return " or ".join(t.value for t in types)
