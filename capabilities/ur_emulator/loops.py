"""The emulator's two kinds of loop: a client's lines, and a cycle at a fixed rate."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

__all__ = ["next_cycle", "received_lines"]


def received_lines(
    conn: socket.socket, stop: threading.Event, encoding: str, chunk_size: int
) -> Iterator[str]:
    """The lines a client sends, decoded and stripped, until it hangs up or ``stop`` is set."""
    pending = b""
    while not stop.is_set():
        chunk = conn.recv(chunk_size)
        if not chunk:
            return
        pending += chunk
        while b"\n" in pending:
            line, pending = pending.split(b"\n", 1)
            yield line.decode(encoding, "replace").strip()


def next_cycle(next_time: float, period: float, stop: threading.Event) -> float:
    """Wait for the cycle after the one due at ``next_time`` and return when that is due.

    A loop more than a period late drops its backlog and keeps the pace from now.
    """
    next_time += period
    delay = next_time - time.monotonic()
    if delay > 0:
        stop.wait(delay)
    elif delay < -period:
        next_time = time.monotonic()
    return next_time
