"""Whether a process of this host still runs: the one check behind every stale lock and
recovery file (a library save's lock, the Instructor's recovery sidecar).
"""

from __future__ import annotations

import os
import sys

__all__ = ["process_alive"]


def process_alive(pid: int) -> bool:
    """Whether a process of this host has this id (one of another user counts: it is alive)."""
    if pid <= 0:
        return False
    if sys.platform == "win32":
        return _windows_process_alive(pid)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return True  # cannot tell: keep the lock (it goes stale by age)
    return True


def _windows_process_alive(pid: int) -> bool:  # pragma: no cover - Windows only
    """os.kill(pid, 0) would end the process on Windows: ask OpenProcess instead."""
    import ctypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)  # type: ignore[attr-defined,unused-ignore]
    kernel32.OpenProcess.restype = ctypes.c_void_p
    handle = kernel32.OpenProcess(0x1000, False, pid)  # PROCESS_QUERY_LIMITED_INFORMATION
    if not handle:
        return bool(ctypes.get_last_error() == 5)  # type: ignore[attr-defined,unused-ignore]
    try:
        code = ctypes.c_ulong()
        if not kernel32.GetExitCodeProcess(ctypes.c_void_p(handle), ctypes.byref(code)):
            return True
        return bool(code.value == 259)  # STILL_ACTIVE
    finally:
        kernel32.CloseHandle(ctypes.c_void_p(handle))
