"""The runtime bridge: a run of the document's plan on a cell, as Qt signals in the GUI thread."""

from __future__ import annotations

from instructor_app.runtime.controller import RunController, RunOutcome
from instructor_app.runtime.session import CellSession

__all__ = ["CellSession", "RunController", "RunOutcome"]
