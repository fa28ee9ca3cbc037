"""The document: the plan being edited, its undo stack and file; the truth the views show."""

from __future__ import annotations

from instructor_app.document.model import DocumentError, PlanDocument

__all__ = ["DocumentError", "PlanDocument"]
