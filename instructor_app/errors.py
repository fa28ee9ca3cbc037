"""The Instructor's exception root: catch :class:`InstructorError` to catch anything the
application raises on purpose (a refused edit, an autosave that could not be written).
"""

from __future__ import annotations

__all__ = ["InstructorError"]


class InstructorError(Exception):
    """Base of the errors the instructor_app package raises on purpose."""
