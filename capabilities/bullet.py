"""The one place that imports pybullet: quietly, without its "pybullet build time" banner.

pybullet's C extension writes the banner on import straight to a file descriptor (standard
error in pybullet 3.2.6, standard output in some builds), past ``sys.stdout`` and
``sys.stderr``; our commands' output must not carry it. So descriptors 1 and 2 point at the
null device during the import, and C's stdio buffers are flushed before they are restored
(a banner buffered for a pipe would otherwise be written at exit). Every module of the
project imports pybullet from here (``from capabilities.bullet import pybullet``).
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import os
import sys
import threading
from collections.abc import Iterator
from types import ModuleType

__all__ = ["import_quietly", "pybullet"]

_LOCK = threading.Lock()
_QUIET_FDS = (1, 2)


def import_quietly(name: str = "pybullet") -> ModuleType:
    """Import ``name`` with file descriptors 1 and 2 sent to the null device meanwhile.

    Args:
        name: the module to import (pybullet, or one of its submodules).

    Returns:
        The module (from ``sys.modules`` when already imported: then nothing is redirected).
    """
    if name in sys.modules:
        return sys.modules[name]
    with _LOCK, _descriptors_silenced(_QUIET_FDS):
        return importlib.import_module(name)


@contextlib.contextmanager
def _descriptors_silenced(fds: tuple[int, ...]) -> Iterator[None]:
    """Point ``fds`` at the null device inside the block (a missing descriptor is skipped)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()
    saved: dict[int, int] = {}
    for fd in fds:
        with contextlib.suppress(OSError):  # no such descriptor (a detached process)
            saved[fd] = os.dup(fd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in saved:
            os.dup2(devnull, fd)
        yield
    finally:
        _flush_c_stdio()
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)


def _flush_c_stdio() -> None:
    """Flush C's stdio buffers (``fflush(NULL)``), where a buffered banner may wait."""
    with contextlib.suppress(OSError, AttributeError):  # no C library (not Linux or macOS)
        ctypes.CDLL(None).fflush(None)


pybullet = import_quietly("pybullet")
