"""Parameter type -> editor widget, and the rows of the inspector built from them."""

from __future__ import annotations

from engine.units import format_value
from instructor_app.inspectors.base import EditorContext, InspectorError, ParamEditor
from instructor_app.inspectors.factory import (
    EDITOR_TYPES,
    concrete_types,
    default_value,
    editor_for,
)

__all__ = [
    "EDITOR_TYPES",
    "EditorContext",
    "InspectorError",
    "ParamEditor",
    "concrete_types",
    "default_value",
    "editor_for",
    "format_value",
]
