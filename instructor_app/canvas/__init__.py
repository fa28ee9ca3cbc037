"""The canvas: the plan drawn as a behavior tree, a NodeGraphQt view of the document."""

from __future__ import annotations

from instructor_app.canvas.view import PALETTE_MIME, CanvasView

__all__ = ["CanvasView", "PALETTE_MIME"]
