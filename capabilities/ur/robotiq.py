"""A Robotiq gripper through its URCap's socket on the UR controller (port 63352).

The URCap answers ASCII lines (``SET POS 255 SPE 255 FOR 150``, ``GET OBJ``; see the
emulator's ``robotiq.py`` for the variables). Every socket call runs on the UR connection's I/O
thread, like every ur_rtde call: ``open()`` and ``close()`` return at once with a handle that a
monitor on that thread finishes when the gripper reports where it stopped (OBJ): at the
requested position, or on an object while closing, which is what ``is_holding`` reads.
"""

from __future__ import annotations

import socket
import time
from typing import TYPE_CHECKING

from capabilities.robot.commands import CommandHandle
from capabilities.ur.connection import URConnection
from capabilities.ur.errors import URError, ur_words

__all__ = ["ROBOTIQ_PORT", "RobotiqGripper"]

ROBOTIQ_PORT = 63352
_OPEN, _CLOSED = 0, 255
_MOVING, _OBJECT_CLOSING, _ARRIVED = 0, 2, 3
_POLL = 0.02  # s between OBJ polls while a move runs
_TIMEOUT = 10.0  # s for a move to end


class RobotiqGripper:
    """The gripper the gripper capability uses (GripperBackend), through the URCap.

    Args:
        connection: the open UR connection (its I/O thread does the socket work).
        port: the URCap's port.
        speed, force: 0..255 for every move.

    Raises:
        URError: the URCap does not answer or does not activate (at construction).
    """

    def __init__(
        self,
        connection: URConnection,
        port: int = ROBOTIQ_PORT,
        speed: int = 255,
        force: int = 150,
    ) -> None:
        self._conn = connection
        self._port = port
        self._speed, self._force = speed, force
        self._socket: socket.socket | None = None
        self._closed = False
        self._obj = _ARRIVED
        connection.call(self._activate, timeout=15.0)

    # ---------------------------------------------------------------- I/O thread only

    def _ask(self, line: str) -> str:
        if self._socket is None:
            self._socket = socket.create_connection((self._conn.host, self._port), timeout=2.0)
        try:
            self._socket.sendall(line.encode("ascii") + b"\n")
            reply = b""
            while not reply.endswith(b"\n"):
                chunk = self._socket.recv(256)
                if not chunk:
                    raise OSError("the URCap closed the connection")
                reply += chunk
        except OSError:
            self._socket.close()
            self._socket = None
            raise
        return reply.decode("ascii", "replace").strip()

    def _get(self, name: str) -> int:
        reply = self._ask(f"GET {name}").split()
        if len(reply) != 2 or reply[0] != name or not reply[1].isdigit():
            raise URError(f"Robotiq URCap: GET {name} answered {' '.join(reply)!r}")
        return int(reply[1])

    def _set(self, *pairs: tuple[str, int]) -> None:
        line = "SET " + " ".join(f"{name} {value}" for name, value in pairs)
        if self._ask(line) != "ack":
            raise URError(f"Robotiq URCap refused {line!r}")

    def _activate(self) -> None:
        try:
            if self._get("STA") != 3:
                self._set(("ACT", 1))
                deadline = time.monotonic() + 5.0
                while self._get("STA") != 3:
                    if time.monotonic() > deadline:
                        raise URError("the Robotiq gripper did not activate within 5 s")
                    time.sleep(0.05)
                    self._conn.kick()  # a wait on the I/O thread: keep the arm's watchdog fed
            self._closed = self._get("PRE") >= 128
        except OSError as exc:
            raise URError(f"no Robotiq URCap at {self._conn.host}:{self._port}: {exc}") from exc

    # ---------------------------------------------------------------- the backend

    def _move(self, name: str, position: int) -> CommandHandle:
        handle = CommandHandle(name)

        def start() -> None:
            self._set(("POS", position), ("SPE", self._speed), ("FOR", self._force), ("GTO", 1))
            self._closed = position >= 128
            self._obj = _MOVING
            deadline = time.monotonic() + _TIMEOUT
            state = {"next": 0.0}

            def watch(conn: URConnection) -> bool:
                now = time.monotonic()
                if handle.done() or now < state["next"]:
                    return handle.done()
                state["next"] = now + _POLL
                try:
                    if self._get("PRE") == position:  # the URCap took this command
                        self._obj = self._get("OBJ")
                except (OSError, URError) as exc:
                    handle.resolve(False, f"{name}: the gripper stopped answering: {ur_words(exc)}")
                    return True
                if self._obj != _MOVING:
                    handle.resolve(True)
                elif now > deadline:
                    handle.resolve(False, f"{name}: the gripper did not stop within {_TIMEOUT} s")
                return handle.done()

            self._conn.add_monitor(watch)

        def failed(future: object) -> None:
            exc = getattr(future, "exception", lambda: None)()
            if exc is not None:
                handle.resolve(False, f"{name}: {ur_words(exc)}")

        self._conn.submit(start).add_done_callback(failed)
        return handle

    def open(self) -> CommandHandle:
        return self._move("gripper open", _OPEN)

    def close(self) -> CommandHandle:
        return self._move("gripper close", _CLOSED)

    def is_closed(self) -> bool:
        return self._closed

    def is_holding(self) -> bool:
        """Closed and stopped on an object (OBJ 2), as the URCap last reported it."""
        return self._closed and self._obj == _OBJECT_CLOSING


if TYPE_CHECKING:
    from capabilities.gripper.backend import GripperBackend

    def _conforms(gripper: RobotiqGripper) -> GripperBackend:
        return gripper
