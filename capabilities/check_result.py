"""What one check of ``costar doctor`` found (its own module: the computer's checks and a
real cell's checks (:mod:`capabilities.ur.doctor`) both return it).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CheckResult"]


@dataclass(frozen=True)
class CheckResult:
    """What one check found: ``detail`` says what is there (ok) or how to fix it (not ok)."""

    name: str
    ok: bool
    detail: str
