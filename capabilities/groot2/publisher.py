"""Serves a run to Groot2 over ZeroMQ, as BehaviorTree.CPP's ``Groot2Publisher`` does.

A REP socket on PORT answers the requests of :mod:`capabilities.groot2.protocol`; a PUB socket
is bound on PORT+1 as well, where reached breakpoints are announced, as BehaviorTree.CPP does
(nothing else is sent on it: BehaviorTree.CPP publishes no heartbeat or transitions there
either, Groot2 asks). Both are bound to 127.0.0.1 unless another host is given
("*": every interface).

The requests are served on a thread of the publisher's own; the run's events reach it through
:class:`~capabilities.groot2.protocol.Groot2Monitor`, a listener that only updates a buffer
under a short lock, so neither the engine nor the dispatcher thread ever waits on a socket.
"""

from __future__ import annotations

import threading

import zmq

from capabilities.errors import CapabilityError
from capabilities.groot2.protocol import DEFAULT_PORT, Groot2Monitor, error_reply

__all__ = ["DEFAULT_HOST", "Groot2Error", "Groot2Publisher"]

DEFAULT_HOST = "127.0.0.1"
_POLL_MS = 100  # how often the server thread looks whether it should end
_SEND_TIMEOUT_MS = 1000  # as BehaviorTree.CPP: a client that went away does not hang it


class Groot2Error(CapabilityError):
    """The publisher cannot start (a port taken, a host that is not an interface)."""


class Groot2Publisher:
    """Binds the two sockets and serves ``monitor`` until :meth:`close`.

    Args:
        monitor: what is served; add it to the run's listeners.
        port: the REP socket's port (the PUB socket takes the next one).
        host: the interface to bind ("127.0.0.1" by default, "*" for all).

    Raises:
        Groot2Error: a port is taken or the host cannot be bound.
    """

    def __init__(
        self, monitor: Groot2Monitor, port: int = DEFAULT_PORT, host: str = DEFAULT_HOST
    ) -> None:
        if not 1 <= port <= 65534:
            raise Groot2Error(f"the Groot2 port must be from 1 to 65534, not {port}")
        self.monitor = monitor
        self.port = port
        self.host = host
        self._context = zmq.Context()
        self._server = self._context.socket(zmq.REP)
        self._publisher = self._context.socket(zmq.PUB)
        for socket in (self._server, self._publisher):
            socket.setsockopt(zmq.LINGER, 0)
            socket.setsockopt(zmq.SNDTIMEO, _SEND_TIMEOUT_MS)
        try:
            self._bind(self._server, port)
            self._bind(self._publisher, port + 1)
        except Groot2Error:
            self._close_sockets()
            raise
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="costar-groot2", daemon=True)
        self._thread.start()

    def serve(self, monitor: Groot2Monitor) -> None:
        """Serve another run from now on (its tree has a new tree id: Groot2 fetches it)."""
        self.monitor = monitor

    @property
    def address(self) -> str:
        """Where Groot2 connects: host:port."""
        return f"{self.host}:{self.port}"

    def _bind(self, socket: zmq.Socket[bytes], port: int) -> None:
        try:
            socket.bind(f"tcp://{self.host}:{port}")
        except zmq.ZMQError as exc:
            why = (
                "the port is taken (another publisher, another run?)"
                if exc.errno == zmq.EADDRINUSE
                else exc.strerror
            )
            raise Groot2Error(
                f"cannot publish for Groot2 on {self.host}:{port}: {why}; choose another "
                "port with --groot2 PORT (it uses PORT and PORT+1)"
            ) from exc

    def _serve(self) -> None:
        poller = zmq.Poller()
        poller.register(self._server, zmq.POLLIN)
        while not self._stop.is_set():
            try:
                self._announce()
                if not poller.poll(_POLL_MS):
                    continue
                request = self._server.recv_multipart()
                try:
                    reply = self.monitor.handle(request)
                except Exception as exc:  # a bug here must not leave Groot2 unanswered
                    reply = error_reply(f"{type(exc).__name__}: {exc}")
                self._server.send_multipart(reply)
            except zmq.ZMQError:
                if self._stop.is_set():
                    return
                # A reply that could not go out leaves the REP socket waiting to send:
                # start a fresh one on the same port rather than serve nobody.
                self._renew_server()
                poller = zmq.Poller()
                poller.register(self._server, zmq.POLLIN)

    def _announce(self) -> None:
        """Send the reached breakpoints on the PUB socket (this thread's own)."""
        parts = self.monitor.reached_breakpoints()
        for index in range(0, len(parts), 2):
            try:
                self._publisher.send_multipart(parts[index : index + 2])
            except zmq.ZMQError:
                return  # no subscriber keeps up: BehaviorTree.CPP goes on as well

    def _renew_server(self) -> None:
        self._server.close(0)
        self._server = self._context.socket(zmq.REP)
        self._server.setsockopt(zmq.LINGER, 0)
        self._server.setsockopt(zmq.SNDTIMEO, _SEND_TIMEOUT_MS)
        try:
            self._server.bind(f"tcp://{self.host}:{self.port}")
        except zmq.ZMQError:
            self._stop.set()

    def close(self) -> None:
        """Stop serving and free both ports."""
        self._stop.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(2 * _POLL_MS / 1000 + _SEND_TIMEOUT_MS / 1000)
        self._close_sockets()

    def _close_sockets(self) -> None:
        self._server.close(0)
        self._publisher.close(0)
        self._context.term()

    def __enter__(self) -> Groot2Publisher:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
