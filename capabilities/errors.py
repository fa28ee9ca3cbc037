"""The capabilities' exception root: catch :class:`CapabilityError` to catch anything a
capability, a cell or the command line raises on purpose (a bad scene or cell file, a missing
interface, an operation that cannot be made).
"""

from __future__ import annotations

__all__ = ["CapabilityError"]


class CapabilityError(Exception):
    """Base of the errors the capabilities package raises on purpose."""
