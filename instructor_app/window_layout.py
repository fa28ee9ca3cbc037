"""Where the main window's panels go: its docks, their tabs and their first sizes.

Layout only: the window creates the panels and wires them; these functions place them.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, QSize, Qt
from PySide6.QtWidgets import QDockWidget, QMainWindow, QScrollArea, QTabBar, QWidget

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


def _whole_labels(bar: QTabBar) -> None:
    """A tab bar of docks shows its labels whole: never elided, scroll buttons when the
    tabs are wider than the bar.
    """
    bar.setElideMode(Qt.TextElideMode.ElideNone)
    bar.setUsesScrollButtons(True)
    bar.setExpanding(False)
    # Narrower padding than the style's: four tabs' labels fit a 240 px column whole.
    bar.setStyleSheet("QTabBar::tab { padding: 4px 7px; }")


class _WholeTabLabels(QObject):
    """Gives each tab bar the main window makes for its tabbed docks whole labels; the
    window makes them when docks are tabbed together (also later, by the user).
    """

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() in (QEvent.Type.ChildAdded, QEvent.Type.ChildPolished):
            child = event.child()  # type: ignore[attr-defined]
            if isinstance(child, QTabBar):
                _whole_labels(child)
        return False


def whole_tab_labels(window: QMainWindow) -> None:
    """Every tab bar of ``window``'s docks, now and later, shows its labels whole."""
    for bar in window.findChildren(QTabBar):
        _whole_labels(bar)


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
    window._whole_tab_labels = _WholeTabLabels(window)  # type: ignore[attr-defined]
    window.installEventFilter(window._whole_tab_labels)  # type: ignore[attr-defined]
    # The side columns reach down to the status bar: the bottom tabs need less height than
    # the inspector and the cameras.
    window.setCorner(Qt.Corner.BottomLeftCorner, Qt.DockWidgetArea.LeftDockWidgetArea)
    window.setCorner(Qt.Corner.BottomRightCorner, Qt.DockWidgetArea.RightDockWidgetArea)

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
        ("timeline", "Timeline", views.timeline),
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
    otherwise (the canvas and the inspector keep their room). The columns' widths follow
    the window's: the palette's tabs, the inspector's fields and the right-hand tabs read
    whole at 1366 px, the camera pictures are pictures at 1920 px.
    """
    width, across = window.width(), Qt.Orientation.Horizontal
    if width >= 1700:
        right = Qt.DockWidgetArea.RightDockWidgetArea
        window.addDockWidget(right, docks["cameras"], across)  # a full-height column
        window.splitDockWidget(docks["cameras"], docks["scene3d"], Qt.Orientation.Vertical)
        window.resizeDocks(
            [docks["cameras"], docks["scene3d"]], [520, 480], Qt.Orientation.Vertical
        )
        window.resizeDocks(
            [docks["palette"], docks["inspector"], docks["cameras"]],
            [round(width * 0.14), round(width * 0.18), round(width * 0.3)],
            across,
        )
    else:
        # Below the canvas, beside the log: the right-hand column keeps three tabs that
        # read whole in its width, and the pictures get the bottom's breadth.
        window.tabifyDockWidget(docks["inside"], docks["cameras"])
        window.tabifyDockWidget(docks["cameras"], docks["scene3d"])
        docks["plan"].raise_()
        docks["validation"].raise_()
        window.resizeDocks([docks["palette"], docks["inspector"]], [240, 320], across)
    whole_tab_labels(window)
