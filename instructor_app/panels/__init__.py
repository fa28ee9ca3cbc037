"""Side panels of the Instructor: palette, inspector, validation, blackboard, log, the plan's
settings, its waypoints and the subtree library.
"""

from __future__ import annotations

from instructor_app.panels.blackboard import BlackboardPanel
from instructor_app.panels.inspector import InspectorPanel
from instructor_app.panels.instance_inside import InstanceInsidePanel
from instructor_app.panels.library import LibraryPanel
from instructor_app.panels.log import LogPanel
from instructor_app.panels.palette import PalettePanel
from instructor_app.panels.plan_settings import PlanSettingsPanel
from instructor_app.panels.validation import ValidationPanel
from instructor_app.panels.waypoints import WaypointsPanel

__all__ = [
    "BlackboardPanel",
    "InspectorPanel",
    "InstanceInsidePanel",
    "LibraryPanel",
    "LogPanel",
    "PalettePanel",
    "PlanSettingsPanel",
    "ValidationPanel",
    "WaypointsPanel",
]
