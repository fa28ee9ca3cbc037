"""The two views of the cell, the camera panel and the 3D scene, and what they share: the
cell in use, the plan's regions and waypoints, and regions drawn by pointing (saved in the
plan through the document, one undo command each).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Signal

from instructor_app.document.editing import PlanDocument
from instructor_app.document.regions import plan_regions, save_region
from instructor_app.panels.cameras import CameraPanel
from instructor_app.panels.scene3d import Scene3DPanel
from instructor_app.runtime.session import CellSession

__all__ = ["CellViews"]


class CellViews(QObject):
    """Creates and feeds the camera panel and the 3D scene.

    Args:
        document: the plan (its regions and waypoints are shown; drawn regions go in it).
        session: the cell in use.
        selected_node: the id of the node selected on the canvas, or None (a drawn region
            goes to its Region port when it has one).
        region_name: the plan parameter a drawn region goes to otherwise.

    Signals:
        message(str): for the status bar.
    """

    message = Signal(str)

    def __init__(
        self,
        document: PlanDocument,
        session: CellSession,
        selected_node: Callable[[], str | None],
        region_name: str = "REGION",
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.session = session
        self._selected = selected_node
        self.region_name = region_name
        self.cameras = CameraPanel()
        self.scene3d = Scene3DPanel()
        self.scene3d.set_frame_source(self._latest_frame)
        for panel in (self.cameras, self.scene3d):
            panel.region_drawn.connect(self.save_region)
            panel.message.connect(self.message)
        session.cell_changed.connect(lambda _name: self.set_cell(session.cell))
        document.plan_changed.connect(self._show_plan)
        document.plan_reset.connect(self._show_plan)
        self.set_cell(session.cell)

    def _latest_frame(self, camera: str) -> Any:
        feed = self.cameras.feed
        return feed.latest(camera) if feed is not None else None

    def set_cell(self, cell: Any) -> None:
        self.cameras.set_cell(cell)
        self.scene3d.set_cell(cell)
        self._show_plan()

    def _show_plan(self) -> None:
        plan = self.document.plan
        regions = plan_regions(plan)
        self.cameras.set_regions(regions)
        self.scene3d.set_regions(regions)
        self.scene3d.set_waypoints(plan.waypoints)

    def save_region(self, region: Any) -> str:
        """Save a drawn region (an ``engine.types.Region``) in the plan; returns where it went."""
        where = save_region(self.document, region, self._selected(), self.region_name)
        c = region.center
        self.message.emit(
            f"Region ({c[0] * 1000:.0f}, {c[1] * 1000:.0f}, {c[2] * 1000:.0f}) mm, "
            f"r {region.radius * 1000:.0f} mm saved to {where}"
        )
        return where

    def stop(self) -> None:
        """Stop the camera feed and the 3D refresh (before the cell closes)."""
        self.cameras.stop()
        self.scene3d.stop()
