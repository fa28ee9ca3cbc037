"""The built-in ``debug`` capability: always available, for tests, teaching and dry runs."""

from __future__ import annotations

from capabilities.debug.operations import capability

__all__ = ["capability"]
