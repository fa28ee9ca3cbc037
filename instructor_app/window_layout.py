"""Where the main window's panels go: its docks, their tabs and their first sizes.

Layout only: the window creates the panels and wires them; these functions place them.
"""

from __future__ import annotations

from PySide6.QtCore import QSize, Qt
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QWidget

from instructor_app.panels.cell_views import CellViews
from instructor_app.views import Views


class _Scrolled(QScrollArea):
    """A tall panel in a scroll area that asks for no more than a side column's width, so
    that its tab squeezes neither the inspector nor the palette.
    """

    def sizeHint(self) -> QSize:
        hint = super().sizeHint()
        return QSize(min(hint.width(), 260), hint.height())


def _scrolled(widget: QWidget) -> QScrollArea:
    area = _Scrolled()
    area.setWidgetResizable(True)
    area.setWidget(widget)
    return area


def place_docks(
    window: QMainWindow,
    views: Views,
    cell_views: CellViews,
    operator_panel: QWidget,
    running_panel: QWidget,
) -> dict[str, QDockWidget]:
    """Put every panel in a dock of ``window``; returns the docks by name.

    The cameras and the 3D scene are placed by :func:`arrange_cell_views` afterwards (when
    no saved layout is restored), as their place depends on the window's width.
    """
    docks: dict[str, QDockWidget] = {}

    def dock(name: str, title: str, widget: QWidget, area: Qt.DockWidgetArea) -> None:
        docks[name] = QDockWidget(title, window)
        docks[name].setObjectName(f"{name}_dock")  # saveState needs names
        docks[name].setWidget(widget)
        window.addDockWidget(area, docks[name])

    area, vertical = Qt.DockWidgetArea, Qt.Orientation.Vertical
    dock("palette", "Palette", views.palette, area.LeftDockWidgetArea)
    dock("move", "Move", _scrolled(views.move), area.LeftDockWidgetArea)
    dock("objects", "Objects", views.objects, area.LeftDockWidgetArea)
    window.tabifyDockWidget(docks["palette"], docks["move"])
    window.tabifyDockWidget(docks["move"], docks["objects"])
    docks["palette"].raise_()
    dock("inspector", "Inspector", views.inspector, area.RightDockWidgetArea)
    dock("cameras", "Cameras", cell_views.cameras, area.RightDockWidgetArea)
    dock("scene3d", "3D scene", cell_views.scene3d, area.RightDockWidgetArea)
    dock("plan", "Plan", views.plan_settings, area.RightDockWidgetArea)
    dock("waypoints", "Waypoints", _scrolled(views.waypoints), area.RightDockWidgetArea)
    dock("operator", "Operator", operator_panel, area.RightDockWidgetArea)
    dock("library", "Library", views.library, area.LeftDockWidgetArea)
    window.tabifyDockWidget(docks["palette"], docks["library"])
    docks["palette"].raise_()
    window.splitDockWidget(docks["inspector"], docks["plan"], vertical)
    window.tabifyDockWidget(docks["plan"], docks["waypoints"])
    window.tabifyDockWidget(docks["waypoints"], docks["operator"])
    docks["plan"].raise_()  # the operator tab comes forward when the robot asks
    bottom = [
        ("validation", "Problems", views.validation),
        ("log", "Log", views.log),
        ("blackboard", "Blackboard", views.blackboard),
        ("running", "Running nodes", running_panel),
        ("inside", "Inside instance", views.inside),
    ]
    for name, title, widget in bottom:
        dock(name, title, widget, area.BottomDockWidgetArea)
    first = docks["validation"]
    for name, _, _ in bottom[1:]:
        window.tabifyDockWidget(first, docks[name])
    first.raise_()
    window.resizeDocks([first], [180], vertical)
    # The inspector gets most of the right-hand column; the Plan tabs below it less.
    window.resizeDocks([docks["inspector"], docks["plan"]], [700, 200], vertical)
    window.resizeDocks(
        [docks["palette"], docks["inspector"]], [240, 320], Qt.Orientation.Horizontal
    )
    return docks


def arrange_cell_views(window: QMainWindow, docks: dict[str, QDockWidget]) -> None:
    """Cameras above the 3D scene in a column of their own right of the inspector when
    the window is wide enough for it (1700 px); tabs beside Plan, Waypoints and Operator
    otherwise (the canvas and the inspector keep their room).
    """
    if window.width() >= 1700:
        right, across = Qt.DockWidgetArea.RightDockWidgetArea, Qt.Orientation.Horizontal
        window.addDockWidget(right, docks["cameras"], across)  # a full-height column
        window.splitDockWidget(docks["cameras"], docks["scene3d"], Qt.Orientation.Vertical)
        window.resizeDocks(
            [docks["cameras"], docks["scene3d"]], [420, 480], Qt.Orientation.Vertical
        )
        window.resizeDocks([docks["palette"], docks["cameras"]], [240, 560], across)
    else:
        window.tabifyDockWidget(docks["operator"], docks["cameras"])
        window.tabifyDockWidget(docks["cameras"], docks["scene3d"])
        docks["plan"].raise_()
