"""The engine's exception base: catch :class:`EngineError` to catch anything the engine raises
on purpose (a bad plan file, a plan that does not validate).
"""

from __future__ import annotations

__all__ = ["EngineError"]


class EngineError(Exception):
    """Base of the errors the engine raises on purpose."""
