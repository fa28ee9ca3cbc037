"""The one place that imports pybullet: quietly, without its "pybullet build time" banner.

pybullet's C extension prints the banner with ``printf`` on import, straight to file
descriptor 1, past ``sys.stdout``; our commands' output must not carry it. Every module of the
project imports pybullet from here (``from capabilities.bullet import pybullet``).
"""

from __future__ import annotations

import importlib
import os
import sys
import threading
from types import ModuleType

__all__ = ["import_quietly", "pybullet"]

_LOCK = threading.Lock()


def import_quietly(name: str = "pybullet") -> ModuleType:
    """Import ``name`` with file descriptor 1 sent to the null device during the import.

    Args:
        name: the module to import (pybullet, or one of its submodules).

    Returns:
        The module (from ``sys.modules`` when already imported: then nothing is redirected).
    """
    if name in sys.modules:
        return sys.modules[name]
    with _LOCK:
        try:
            sys.stdout.flush()
        except (OSError, ValueError):
            pass
        try:
            saved = os.dup(1)
        except OSError:  # no file descriptor 1 (a detached process): nothing to hide
            return importlib.import_module(name)
        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, 1)
            return importlib.import_module(name)
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            os.close(devnull)


pybullet = import_quietly("pybullet")
