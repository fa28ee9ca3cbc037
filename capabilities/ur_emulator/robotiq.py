"""The Robotiq gripper URCap's socket (port 63352), answered by the simulated cell's gripper.

The URCap speaks ASCII lines: ``SET <VAR> <value> [<VAR> <value> ...]`` answered ``ack``, and
``GET <VAR>`` answered ``<VAR> <value>``. Variables: ACT (activate), GTO (go to the requested
position), POS (requested position on SET, actual position on GET; 0 open .. 255 closed), SPE
and FOR (speed and force, 0..255), PRE (the requested position, echoed), STA (0 reset,
3 active), OBJ (0 moving, 1 stopped on contact while opening, 2 stopped on an object while
closing, 3 at the requested position), FLT (fault, 0). The simulated gripper opens or closes
(it has no positions in between): a requested position from 128 on closes it.
"""

from __future__ import annotations

import socket
import threading
from typing import TYPE_CHECKING

from capabilities.ur_emulator.loops import received_lines

if TYPE_CHECKING:
    from capabilities.robot.commands import CommandHandle
    from capabilities.ur_emulator.controller import EmulatedController

__all__ = ["ROBOTIQ_PORT", "RobotiqURCap", "robotiq_client"]

ROBOTIQ_PORT = 63352
_VARIABLES = ("ACT", "GTO", "POS", "SPE", "FOR", "PRE", "STA", "OBJ", "FLT")
_CLOSE_FROM = 128


class RobotiqURCap:
    """The URCap's registers over the simulated gripper (any thread)."""

    def __init__(self, ctl: EmulatedController) -> None:
        self._ctl = ctl
        self._lock = threading.Lock()
        self._values = dict.fromkeys(_VARIABLES, 0)
        self._values.update(SPE=255, FOR=150)
        self._move: CommandHandle | None = None
        self._closing = False
        self._open_gap = 0.0

    def set(self, pairs: list[tuple[str, int]]) -> bool:
        """Apply ``SET`` pairs; False for an unknown variable or a value out of 0..255."""
        if not pairs or any(n not in _VARIABLES or not 0 <= v <= 255 for n, v in pairs):
            return False
        with self._lock:
            for name, value in pairs:
                if name == "POS":
                    self._values["PRE"] = value
                elif name in ("ACT", "GTO", "SPE", "FOR"):
                    self._values[name] = value
            if self._values["ACT"] == 0:
                self._values.update(STA=0, GTO=0)
            elif self._values["STA"] != 3:
                self._values["STA"] = 3  # activation: the fingers already know their range
                self._open_gap = max(self._open_gap, self._ctl.cell.gripper.gap())
            if (
                self._values["STA"] == 3
                and self._values["GTO"]
                and (any(n in ("POS", "GTO") for n, _ in pairs))
            ):
                self._go(self._values["PRE"] >= _CLOSE_FROM)
        return True

    def _go(self, close: bool) -> None:
        gripper = self._ctl.cell.gripper
        self._closing = close
        self._values["OBJ"] = 0
        self._move = gripper.close() if close else gripper.open()

    def get(self, name: str) -> int | None:
        """The value of ``name`` (None: no such variable)."""
        if name not in _VARIABLES:
            return None
        with self._lock:
            self._update()
            if name == "POS":
                return self._position()
            return self._values[name]

    def _update(self) -> None:
        move = self._move
        if move is None or not move.done():
            return
        self._move = None
        holding = self._ctl.cell.gripper.is_holding()
        self._values["OBJ"] = 2 if self._closing and holding else 3

    def _position(self) -> int:
        gap = self._ctl.cell.gripper.gap()
        self._open_gap = max(self._open_gap, gap)
        if self._open_gap <= 0:
            return 0
        return round(255 * min(1.0, max(0.0, 1.0 - gap / self._open_gap)))


def robotiq_reply(urcap: RobotiqURCap, line: str) -> str:
    """The URCap's answer to one line."""
    words = line.split()
    if len(words) >= 2 and words[0] == "GET":
        value = urcap.get(words[1])
        return f"{words[1]} {value}" if value is not None else "?"
    if len(words) >= 3 and words[0] == "SET" and len(words) % 2 == 1:
        try:
            pairs = [(words[i], int(words[i + 1])) for i in range(1, len(words), 2)]
        except ValueError:
            return "?"
        return "ack" if urcap.set(pairs) else "?"
    return "?"


def robotiq_client(conn: socket.socket, ctl: EmulatedController, stop: threading.Event) -> None:
    """Serve one URCap client: a line in, a line out."""
    urcap = ctl.robotiq
    for line in received_lines(conn, stop, "ascii", 1024):
        conn.sendall(robotiq_reply(urcap, line).encode("ascii") + b"\n")
