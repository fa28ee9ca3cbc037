"""The document: the plan being edited, its undo stack and file; the truth the views show."""

from __future__ import annotations

from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError, PlanModel

__all__ = ["DocumentError", "PlanDocument", "PlanModel"]
