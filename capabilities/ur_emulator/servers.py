"""The emulator's TCP servers: dashboard (29999), script port (30003) and RTDE (30004).

Each server accepts on a loopback address only and serves each client on its own thread.
"""

from __future__ import annotations

import contextlib
import ipaddress
import itertools
import logging
import re
import socket
import struct
import threading
import time
from collections.abc import Callable
from typing import Any

from capabilities.ur_emulator import wire
from capabilities.ur_emulator.controller import EmulatedController
from capabilities.ur_emulator.dashboard import dashboard_reply
from capabilities.ur_emulator.errors import EmulatorError
from capabilities.ur_emulator.loops import next_cycle, received_lines

__all__ = ["Server", "check_loopback", "rtde_client", "script_client", "dashboard_client"]

_log = logging.getLogger(__name__)
_LOOPBACK = ipaddress.ip_network("127.0.0.0/8")


def check_loopback(host: str) -> str:
    """``host`` if it is an IPv4 loopback address (127.0.0.0/8).

    Raises:
        EmulatorError: any other address (the emulator never listens beyond this machine).
    """
    try:
        address = ipaddress.ip_address(host)
    except ValueError:
        raise EmulatorError(
            f"emulator host {host!r} is not an IP address: give a loopback address "
            "such as 127.0.0.2"
        ) from None
    if address not in _LOOPBACK:
        raise EmulatorError(
            f"emulator host {host} is not a loopback address: the emulator binds only to "
            "127.0.0.0/8 (for example 127.0.0.2)"
        )
    return host


Handler = Callable[[socket.socket, EmulatedController, threading.Event], None]


class Server:
    """A listening socket on (host, port); one thread per client running ``handler``."""

    def __init__(
        self, host: str, port: int, controller: EmulatedController, handler: Handler
    ) -> None:
        self._ctl = controller
        self._handler = handler
        self._closing = threading.Event()
        self._clients: list[socket.socket] = []
        self._lock = threading.Lock()
        self._refuse_until = 0.0  # monotonic s: a network outage until then (see drop_clients)
        self._listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._listener.bind((check_loopback(host), port))
        except OSError as exc:
            self._listener.close()
            raise EmulatorError(f"cannot listen on {host}:{port}: {exc}") from exc
        self._listener.listen(8)
        self._thread = threading.Thread(
            target=self._accept, name=f"ur-emulator-{port}", daemon=True
        )
        self._thread.start()

    def _accept(self) -> None:
        while not self._closing.is_set():
            try:
                conn, _ = self._listener.accept()
            except OSError:
                return
            if time.monotonic() < self._refuse_until:  # the outage: nothing gets through
                _close(conn)
                continue
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                if self._closing.is_set():
                    conn.close()
                    return
                self._clients.append(conn)
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn: socket.socket) -> None:
        stop = threading.Event()
        try:
            self._handler(conn, self._ctl, stop)
        except (OSError, EOFError):
            pass
        except Exception:
            _log.exception("emulator client handler failed")
        finally:
            stop.set()
            _close(conn)
            with self._lock:
                if conn in self._clients:
                    self._clients.remove(conn)

    def drop_clients(self, outage: float = 0.0) -> None:
        """Close every client connection (the listener stays); for ``outage`` s after, a
        connection is closed as soon as it is made, as if the network were still down.
        """
        self._refuse_until = time.monotonic() + outage
        with self._lock:
            clients, self._clients = self._clients, []
        for conn in clients:
            _close(conn)

    def close(self) -> None:
        """Stop listening and close every client."""
        self._closing.set()
        _close(self._listener)
        self.drop_clients()
        self._thread.join(timeout=5.0)


def _close(sock: socket.socket) -> None:
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)
    sock.close()


def _read_exact(conn: socket.socket, size: int) -> bytes:
    data = b""
    while len(data) < size:
        chunk = conn.recv(size - len(data))
        if not chunk:
            raise EOFError
        data += chunk
    return data


def dashboard_client(conn: socket.socket, ctl: EmulatedController, stop: threading.Event) -> None:
    """Serve one dashboard client: a line in, a line out."""
    conn.sendall(b"Connected: Universal Robots Dashboard Server\n")
    for line in received_lines(conn, stop, "utf-8", 4096):
        reply, close = dashboard_reply(ctl, line)
        conn.sendall(reply.encode() + b"\n")
        if close:
            return


_OFFSET = re.compile(rb"reg_offset_int\s*=\s*(\d+)")


_script_ids = itertools.count(1)


def script_client(conn: socket.socket, ctl: EmulatedController, stop: threading.Event) -> None:
    """Take scripts sent to the script port; ur_rtde's control script starts the program.

    Each connection is one client (numbered from 1): the controller tells the clients that
    upload a control script apart (a second one takes the robot from the first).
    """
    client = next(_script_ids)
    ctl.script_client(client)
    pending = b""
    try:
        while not stop.is_set():
            chunk = conn.recv(65536)
            if not chunk:
                return
            pending += chunk
            if pending.lstrip().startswith(b"def ") and pending.rstrip().endswith(b"\nend"):
                if b"def rtde_control" in pending:
                    match = _OFFSET.search(pending)
                    ctl.load_script(int(match.group(1)) if match else 0, client)
                else:
                    ctl.end_program("a script the emulator does not run replaced the program")
                    ctl.text("custom scripts are not emulated")
                pending = b""
    finally:
        ctl.script_client(client, connected=False)


class _RTDESession:
    """One RTDE client: its recipes and its data stream."""

    def __init__(self, conn: socket.socket, ctl: EmulatedController, stop: threading.Event):
        self.conn = conn
        self.ctl = ctl
        self.stop = stop
        self.send_lock = threading.Lock()
        self.inputs: dict[int, tuple[list[str], list[str], struct.Struct]] = {}
        self.output: tuple[list[str], struct.Struct, float] | None = None
        self.streaming = threading.Event()
        self.sender: threading.Thread | None = None

    def send(self, kind: int, payload: bytes = b"") -> None:
        with self.send_lock:
            self.conn.sendall(wire.pack_message(kind, payload))

    def handle(self, kind: int, body: bytes) -> None:
        if kind == wire.REQUEST_PROTOCOL_VERSION:
            (version,) = struct.unpack(">H", body[:2])
            self.send(kind, bytes([1 if version in (1, 2) else 0]))
        elif kind == wire.GET_URCONTROL_VERSION:
            self.send(kind, struct.pack(">IIII", *self.ctl.version))
        elif kind == wire.SETUP_OUTPUTS:
            self._setup_outputs(body)
        elif kind == wire.SETUP_INPUTS:
            names = [n for n in body.decode().split(",") if n]
            types = [wire.input_type(n) for n in names]
            recipe = len(self.inputs) + 1
            if "NOT_FOUND" not in types:
                self.inputs[recipe] = (names, types, struct.Struct(wire.recipe_format(types)))
            self.send(kind, bytes([recipe]) + ",".join(types).encode())
        elif kind == wire.START:
            self.send(kind, bytes([1 if self.output is not None else 0]))
            if self.output is not None:
                self._start_stream()
        elif kind == wire.PAUSE:
            self.streaming.clear()
            self.send(kind, bytes([1]))
        elif kind == wire.DATA_PACKAGE:
            self._data(body)

    def _setup_outputs(self, body: bytes) -> None:
        (frequency,) = struct.unpack(">d", body[:8])
        names = [n for n in body[8:].decode().split(",") if n]
        types = [wire.output_type(n) for n in names]
        if "NOT_FOUND" not in types:
            rate = min(frequency, self.ctl.frequency) if frequency > 0 else self.ctl.frequency
            self.output = (names, struct.Struct(wire.recipe_format(types)), rate)
        self.send(wire.SETUP_OUTPUTS, bytes([1]) + ",".join(types).encode())

    def _data(self, body: bytes) -> None:
        recipe = self.inputs.get(body[0])
        if recipe is None:
            return
        names, types, layout = recipe
        flat = list(layout.unpack(body[1 : 1 + layout.size]))
        values: dict[str, Any] = {}
        for name, kind in zip(names, types, strict=True):
            width = wire.width(kind)
            values[name] = flat[0] if width == 1 else tuple(flat[:width])
            del flat[:width]
        self.ctl.write_inputs(values)

    def _start_stream(self) -> None:
        self.streaming.set()
        if self.sender is None:
            self.sender = threading.Thread(target=self._stream, daemon=True)
            self.sender.start()

    def _stream(self) -> None:
        assert self.output is not None
        names, layout, rate = self.output
        period = 1.0 / rate
        next_time = time.monotonic()
        while not self.stop.is_set():
            if self.streaming.is_set():
                snap = self.ctl.snapshot()
                flat: list[Any] = []
                for name in names:
                    value = snap.get(name)
                    if value is None:
                        value = self.ctl.default_value(name)
                    if isinstance(value, (tuple, list)):
                        flat.extend(value)
                    else:
                        flat.append(value)
                try:
                    self.send(wire.DATA_PACKAGE, bytes([1]) + layout.pack(*flat))
                except OSError:
                    return
            next_time = next_cycle(next_time, period, self.stop)


def rtde_client(conn: socket.socket, ctl: EmulatedController, stop: threading.Event) -> None:
    """Serve one RTDE client until it disconnects."""
    session = _RTDESession(conn, ctl, stop)
    ctl.add_input_socket(conn)  # the watchdog asks whether its bytes wait unread
    try:
        while not stop.is_set():
            size, kind = struct.unpack(">HB", _read_exact(conn, 3))
            body = _read_exact(conn, size - 3) if size > 3 else b""
            session.handle(kind, body)
    finally:
        ctl.add_input_socket(conn, present=False)
