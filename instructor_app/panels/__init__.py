"""Side panels of the Instructor: palette, inspector, validation, blackboard and log."""

from __future__ import annotations

from instructor_app.panels.blackboard import BlackboardPanel
from instructor_app.panels.inspector import InspectorPanel
from instructor_app.panels.log import LogPanel
from instructor_app.panels.palette import PalettePanel
from instructor_app.panels.validation import ValidationPanel

__all__ = ["BlackboardPanel", "InspectorPanel", "LogPanel", "PalettePanel", "ValidationPanel"]
