"""The canvas and panels of the main window: the one place that knows their APIs."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtGui import QAction
from PySide6.QtWidgets import QWidget

from engine.spec import NodeKind
from instructor_app.document.editing import PlanDocument
from instructor_app.node_factory import PaletteItem, make_node, manifest_or_none, readable
from instructor_app.runtime.session import CellSession

__all__ = ["CANVAS_ACTIONS", "Views", "make_views"]

CANVAS_ACTIONS = (
    "cut",
    "copy",
    "paste",
    "duplicate",
    "delete",
    "move_left",
    "move_right",
    "toggle_collapse",
    "auto_layout",
)


@dataclass
class Views:
    """The canvas and panels the window shows; the one place that knows their APIs."""

    canvas: Any
    canvas_actions: dict[str, QAction]
    palette: Any
    inspector: Any
    validation: Any
    blackboard: Any
    log: Any
    plan_settings: Any
    waypoints: Any
    library: Any
    inside: Any
    teacher: Any = None  # RobotTeacher: jog, freedrive, move-here off the GUI thread
    move: Any = None
    objects: Any = None
    timeline: Any = None

    def set_registry(self, registry: Any) -> None:
        """Another cell: every view that shows operations rebuilds from its registry."""
        views = (self.teacher, self.objects, self.palette, self.inspector, self.validation)
        for view in (*views, self.waypoints):
            view.set_registry(registry)
        self.canvas.set_operation_kinds({m.id: m.kind for m in registry.manifests()})
        operations: dict[str, list[tuple[str, str]]] = {}
        for item in self.palette.items():
            if item.op is not None and item.available:
                title = item.group.replace("_", " ").capitalize()
                operations.setdefault(title, []).append((item.label, item.op))
        self.canvas.set_operations(operations)
        self.inspector.set_object_names(offered_object_names(registry.cell.interfaces()))


def offered_object_names(interfaces: Any) -> list[str]:
    """The object models a field offers: those the cell's scene has on the table first (what a
    plan usually handles), then the rest of the library by name.
    """
    library = interfaces.get("objects")
    names = list(library.names()) if library is not None else []
    layout = interfaces.get("scene_layout") or {}
    on_table = [name for name in layout.get("objects", []) if name in names]
    return on_table + [name for name in names if name not in on_table]


def _item_for(kind: NodeKind, op: str | None) -> PaletteItem:
    """The palette item of a canvas drop or "Add child" (the canvas passes kind and op)."""
    label = readable(op or kind.value)
    return PaletteItem(kind, op, label, "", "")


def make_views(
    document: PlanDocument, session: CellSession, parent: QWidget, data_folder: Path | None = None
) -> Views:
    """Create the canvas and the panels for ``document`` on the session's cell; caches (the
    object thumbnails) go under ``data_folder`` (default: the user's cache folder).
    """
    from instructor_app.canvas import CanvasView
    from instructor_app.panels import (
        BlackboardPanel,
        InspectorPanel,
        InstanceInsidePanel,
        LibraryPanel,
        LogPanel,
        PalettePanel,
        PlanSettingsPanel,
        ValidationPanel,
        WaypointsPanel,
    )
    from instructor_app.panels.move import MovePanel
    from instructor_app.panels.object_library import ObjectLibraryPanel
    from instructor_app.panels.object_thumbnails import ThumbnailCache
    from instructor_app.panels.timeline import TimelinePanel
    from instructor_app.runtime.teach import RobotTeacher

    registry = session.registry
    canvas = CanvasView(document, parent)
    teacher = RobotTeacher(registry, parent=parent)
    canvas.set_node_factory(
        lambda kind, op: make_node(_item_for(kind, op), manifest_or_none(session.registry, op))
    )
    actions = {name: canvas.action(name) for name in CANVAS_ACTIONS}
    views = Views(
        canvas,
        actions,
        PalettePanel(registry, parent),
        InspectorPanel(document, registry, parent),
        ValidationPanel(document, registry, parent),
        BlackboardPanel(parent),
        LogPanel(parent=parent),
        PlanSettingsPanel(document, parent),
        WaypointsPanel(document, registry, parent, teacher=teacher),
        LibraryPanel(parent),
        InstanceInsidePanel(parent),
        teacher,
        MovePanel(teacher, parent),
        ObjectLibraryPanel(
            thumbnails=ThumbnailCache(data_folder / "thumbnails") if data_folder else None,
            parent=parent,
        ),
        TimelinePanel(parent),
    )
    views.inspector.set_teacher(teacher)
    views.set_registry(registry)
    return views
