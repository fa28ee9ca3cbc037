"""BehaviorTree.CPP's Groot2 protocol (``loggers/groot2_protocol.h``, version 2), without sockets.

Every exchange is a multipart ZeroMQ request and reply. A request's first part is a 6-byte
header: the protocol id (1 byte, 2), the request type (1 byte, an ASCII letter) and a unique
id (uint32, little-endian, chosen by the client). A reply's first part echoes those 6 bytes
and adds the tree id, 16 bytes (a random version-4 UUID made once per publisher, as
BehaviorTree.CPP does). What follows depends on the request:

- FULLTREE (``T``): the loaded tree's XML (:mod:`engine.btcpp.runtime`).
- STATUS (``S``): 3 bytes per node, the ``_uid`` (uint16) and its status (IDLE 0, RUNNING 1,
  SUCCESS 2, FAILURE 3, SKIPPED 4; a node reset to IDLE is 10 + the status it had), the
  nodes of the main tree first, then those of each instance, each in the order they were made.
- BLACKBOARD (``B``, a second part "name;name"): MessagePack of ``{name: {key: value}}`` for
  the named instances (the main tree by its tree id, an instance by its ``_fullpath``).
- TOGGLE_RECORDING (``r``, "start" or "stop"): on start, the wall time in microseconds as
  text; GET_TRANSITIONS (``t``): 9 bytes per status change since, the microseconds since the
  start (6 bytes), the ``_uid`` (uint16) and the new status (1 byte); the last 1000 are kept.
- The hooks (breakpoints): HOOK_INSERT, HOOK_REMOVE and BREAKPOINT_UNLOCK (a JSON second
  part), HOOKS_DUMP (a JSON list), REMOVE_ALL_HOOKS and DISABLE_ALL_HOOKS are served by the
  run's :class:`~capabilities.groot2.hooks.Groot2Hooks` (the engine's debugger); a reached
  breakpoint is announced on the PUB socket as a BREAKPOINT_REACHED request header and the
  ``_uid`` as text (:meth:`Groot2Monitor.reached_breakpoints`). Without hooks (a monitor
  with no run to pause) HOOKS_DUMP answers ``[]``, REMOVE_ALL_HOOKS and DISABLE_ALL_HOOKS the
  bare header, the other three the error reply.

A request that cannot be served gets BehaviorTree.CPP's error reply: two parts, ``error`` and
the reason. Numbers are little-endian, as BehaviorTree.CPP writes them on the machines it
runs on (it copies them from memory).

:class:`Groot2Monitor` keeps what a run shows (it is a run listener) and answers requests;
it is safe to call from the dispatcher thread and a server thread at once.
"""

from __future__ import annotations

import collections
import enum
import json
import secrets
import struct
import threading
import time
import uuid
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import msgpack

from capabilities.base import CapabilityError
from capabilities.groot2.hooks import Groot2Hooks, HookRefused
from engine.btcpp.runtime import LoadedTree
from engine.events import BlackboardWritten, Event, RunPaused, StatusChanged
from engine.status import Status
from engine.types import encode_value

__all__ = [
    "DEFAULT_PORT",
    "PROTOCOL_ID",
    "Groot2Monitor",
    "ProtocolError",
    "ReplyHeader",
    "RequestHeader",
    "RequestType",
    "decode_status",
    "decode_transitions",
    "encode_status",
    "encode_transitions",
    "error_reply",
    "status_code",
]

PROTOCOL_ID = 2
DEFAULT_PORT = 1667  # the REP socket; the PUB socket is on the next port
MAX_TRANSITIONS = 1000
_REQUEST = struct.Struct("<BBI")
_NODE_STATUS = struct.Struct("<HB")
_TRANSITION_TAIL = struct.Struct("<HB")
TREE_ID_SIZE = 16

STATUS_CODES = {
    Status.IDLE: 0,
    Status.RUNNING: 1,
    Status.SUCCESS: 2,
    Status.FAILURE: 3,
    Status.SKIPPED: 4,
}
IDLE_FROM = 10  # a node reset to IDLE: 10 + the status it had


class RequestType(enum.IntEnum):
    """The request types of ``groot2_protocol.h`` (their byte values)."""

    FULLTREE = ord("T")
    STATUS = ord("S")
    BLACKBOARD = ord("B")
    HOOK_INSERT = ord("I")
    HOOK_REMOVE = ord("R")
    BREAKPOINT_REACHED = ord("N")
    BREAKPOINT_UNLOCK = ord("U")
    HOOKS_DUMP = ord("D")
    REMOVE_ALL_HOOKS = ord("A")
    DISABLE_ALL_HOOKS = ord("X")
    TOGGLE_RECORDING = ord("r")
    GET_TRANSITIONS = ord("t")
    UNDEFINED = 0


class ProtocolError(CapabilityError):
    """Bytes that are not a message of the protocol."""


@dataclass(frozen=True)
class RequestHeader:
    """The first part of a request: its type, the client's id for it, the protocol id."""

    type: int
    unique_id: int
    protocol: int = PROTOCOL_ID

    SIZE = _REQUEST.size

    @classmethod
    def new(cls, request_type: RequestType) -> RequestHeader:
        """A header with a random unique id, as a client makes one."""
        return cls(int(request_type), secrets.randbits(32))

    def encode(self) -> bytes:
        return _REQUEST.pack(self.protocol, self.type, self.unique_id)

    @classmethod
    def decode(cls, data: bytes) -> RequestHeader:
        if len(data) != _REQUEST.size:
            raise ProtocolError(f"a request header has {_REQUEST.size} bytes, not {len(data)}")
        protocol, request_type, unique_id = _REQUEST.unpack(data)
        return cls(request_type, unique_id, protocol)


@dataclass(frozen=True)
class ReplyHeader:
    """The first part of a reply: the request's header and the tree id (16 bytes)."""

    request: RequestHeader
    tree_id: bytes

    SIZE = _REQUEST.size + TREE_ID_SIZE

    def encode(self) -> bytes:
        if len(self.tree_id) != TREE_ID_SIZE:
            raise ProtocolError(f"a tree id has {TREE_ID_SIZE} bytes, not {len(self.tree_id)}")
        return self.request.encode() + self.tree_id

    @classmethod
    def decode(cls, data: bytes) -> ReplyHeader:
        if len(data) != cls.SIZE:
            raise ProtocolError(f"a reply header has {cls.SIZE} bytes, not {len(data)}")
        return cls(RequestHeader.decode(data[: _REQUEST.size]), bytes(data[_REQUEST.size :]))


def status_code(old: Status, new: Status) -> int:
    """BehaviorTree.CPP's status byte for a change from ``old`` to ``new``."""
    if new is Status.IDLE and old is not Status.IDLE:
        return IDLE_FROM + STATUS_CODES[old]
    return STATUS_CODES[new]


def encode_status(entries: Iterable[tuple[int, int]]) -> bytes:
    """A STATUS payload: (``_uid``, status byte) pairs, 3 bytes each."""
    return b"".join(_NODE_STATUS.pack(uid, code) for uid, code in entries)


def decode_status(payload: bytes) -> list[tuple[int, int]]:
    """The (``_uid``, status byte) pairs of a STATUS payload, in its order."""
    if len(payload) % _NODE_STATUS.size:
        raise ProtocolError(f"a status payload is 3 bytes a node, not {len(payload)} bytes")
    return [entry for entry in _NODE_STATUS.iter_unpack(payload)]


def encode_transitions(transitions: Iterable[tuple[int, int, int]]) -> bytes:
    """A GET_TRANSITIONS payload: (microseconds, ``_uid``, status) triples, 9 bytes each."""
    parts = []
    for usec, uid, code in transitions:
        parts.append((usec & 0xFFFF_FFFF_FFFF).to_bytes(6, "little"))
        parts.append(_TRANSITION_TAIL.pack(uid, code))
    return b"".join(parts)


def decode_transitions(payload: bytes) -> list[tuple[int, int, int]]:
    """The (microseconds, ``_uid``, status) triples of a GET_TRANSITIONS payload."""
    if len(payload) % 9:
        raise ProtocolError(f"transitions are 9 bytes each, not {len(payload)} bytes in all")
    found = []
    for offset in range(0, len(payload), 9):
        usec = int.from_bytes(payload[offset : offset + 6], "little")
        uid, code = _TRANSITION_TAIL.unpack_from(payload, offset + 6)
        found.append((usec, uid, code))
    return found


def error_reply(message: str) -> list[bytes]:
    """BehaviorTree.CPP's reply to a request it cannot serve."""
    return [b"error", message.encode("utf-8")]


UNSUPPORTED_HOOKS = "breakpoints are not supported by the CoSTAR publisher"


class Groot2Monitor:
    """What Groot2 sees of a run: the loaded tree, every node's status, the blackboard.

    A run listener (add it to the executor's listeners): status changes and blackboard
    writes update it; :meth:`handle` answers a request from what it holds. Both only take a
    short lock, never wait on anything else.

    Args:
        tree: the loaded tree (:func:`engine.btcpp.runtime.loaded_tree`).
        blackboard: the values before the run (the plan's parameters).
        clock: the events' clock (``time.monotonic``, as the executor's).
        wall: the wall clock (seconds since the epoch) for the start of a recording.
    """

    def __init__(
        self,
        tree: LoadedTree,
        blackboard: dict[str, Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
        wall: Callable[[], float] = time.time,
    ) -> None:
        self.tree = tree
        self.tree_id = uuid.uuid4().bytes  # random, version 4: as BehaviorTree.CPP's
        self._xml = tree.xml.encode("utf-8")
        self._lock = threading.Lock()
        order = tree.order
        self._status = bytearray(encode_status((uid, 0) for uid in order))
        self._offset = {uid: index * 3 + 2 for index, uid in enumerate(order)}
        self._board = dict(blackboard or {})
        self._clock, self._wall = clock, wall
        self._recording: float | None = None  # the clock when the recording started
        self._transitions: collections.deque[tuple[int, int, int]] = collections.deque(
            maxlen=MAX_TRANSITIONS
        )
        self.last_request = 0.0  # the clock at the last request (Groot2 is connected)
        self.hooks: Groot2Hooks | None = None  # Groot2's breakpoints (none: refused)
        self._reached: collections.deque[int] = collections.deque()  # uids to announce

    def reached_breakpoints(self) -> list[bytes]:
        """The PUB messages of the breakpoints reached since the last call, each a
        BREAKPOINT_REACHED header and the ``_uid`` as text (the publisher sends them).
        """
        parts: list[bytes] = []
        while self._reached:
            uid = self._reached.popleft()
            header = RequestHeader.new(RequestType.BREAKPOINT_REACHED).encode()
            parts.extend([header, str(uid).encode("ascii")])
        return parts

    # ---------------------------------------------------------------- the run (a listener)

    def __call__(self, event: Event) -> None:
        if isinstance(event, StatusChanged):
            uid = self.tree.uids.get(event.node_id)
            if uid is None:  # the root, which BehaviorTree.CPP has no node for
                return
            code = status_code(event.old, event.new)
            with self._lock:
                self._status[self._offset[uid]] = code
                if self._recording is not None:
                    usec = max(0, round((event.time - self._recording) * 1e6))
                    self._transitions.append((usec, uid, STATUS_CODES[event.new]))
        elif isinstance(event, BlackboardWritten):
            with self._lock:
                self._board[event.key] = event.value
        elif isinstance(event, RunPaused) and self.hooks is not None:
            uid = self.hooks.reached(event.node_id, event.where)
            if uid is not None:
                self._reached.append(uid)

    def statuses(self) -> dict[int, int]:
        """``_uid`` -> status byte now."""
        with self._lock:
            return dict(decode_status(bytes(self._status)))

    # ---------------------------------------------------------------- requests

    def handle(self, parts: Sequence[bytes]) -> list[bytes]:
        """The reply to a request's parts."""
        self.last_request = self._clock()
        if not parts or len(parts[0]) != RequestHeader.SIZE:
            return error_reply("wrong request header")
        request = RequestHeader.decode(parts[0])
        header = ReplyHeader(RequestHeader(request.type, request.unique_id), self.tree_id)
        try:
            body = self._body(request.type, parts)
        except _Refused as exc:
            return error_reply(str(exc))
        return [header.encode(), *body]

    def _body(self, request_type: int, parts: Sequence[bytes]) -> list[bytes]:
        if request_type == RequestType.FULLTREE:
            return [self._xml]
        if request_type == RequestType.STATUS:
            with self._lock:
                return [bytes(self._status)]
        if request_type == RequestType.BLACKBOARD:
            return [self._blackboards(_second(parts).decode("utf-8", "replace"))]
        if request_type == RequestType.TOGGLE_RECORDING:
            return self._toggle(_second(parts))
        if request_type == RequestType.GET_TRANSITIONS:
            with self._lock:
                transitions = list(self._transitions)
                self._transitions.clear()
            return [encode_transitions(transitions)]
        hooks = self.hooks
        if hooks is not None:
            served = _HOOK_REQUESTS.get(request_type)
            if served is not None:
                try:
                    return served(hooks, parts)
                except HookRefused as exc:
                    raise _Refused(str(exc)) from exc
        if request_type == RequestType.HOOKS_DUMP:
            return [b"[]"]
        if request_type in (RequestType.REMOVE_ALL_HOOKS, RequestType.DISABLE_ALL_HOOKS):
            return []
        if request_type in (
            RequestType.HOOK_INSERT,
            RequestType.HOOK_REMOVE,
            RequestType.BREAKPOINT_UNLOCK,
        ):
            raise _Refused(UNSUPPORTED_HOOKS)
        raise _Refused("Request not recognized")

    def _toggle(self, command: bytes) -> list[bytes]:
        if command == b"start":
            with self._lock:
                self._recording = self._clock()
                self._transitions.clear()
            return [str(round(self._wall() * 1e6)).encode("ascii")]
        if command == b"stop":
            with self._lock:
                self._recording = None
        return []

    def _blackboards(self, names: str) -> bytes:
        """MessagePack of ``{name: {key: value}}`` for the instances named "a;b"."""
        wanted = [name for name in names.split(";") if name]
        with self._lock:
            board = dict(self._board)
        dump: dict[str, dict[str, Any]] = {}
        for instance in self.tree.instances:
            name = instance.blackboard_name
            if name not in wanted:
                continue
            prefix = instance.names
            dump[name] = {
                key[len(prefix) :]: _json_value(value)
                for key, value in sorted(board.items())
                if key.startswith(prefix) and "/" not in key[len(prefix) :]
            }
        packed: bytes = msgpack.packb(dump, use_bin_type=True)
        return packed


class _Refused(CapabilityError):
    """A request answered with the error reply."""


def _done(call: Callable[[], None]) -> list[bytes]:
    call()
    return []


_HOOK_REQUESTS: dict[int, Callable[[Groot2Hooks, Sequence[bytes]], list[bytes]]] = {
    RequestType.HOOK_INSERT: lambda h, parts: _done(lambda: h.insert(_second(parts))),
    RequestType.HOOK_REMOVE: lambda h, parts: _done(lambda: h.remove(_second(parts))),
    RequestType.BREAKPOINT_UNLOCK: lambda h, parts: _done(lambda: h.unlock(_second(parts))),
    RequestType.REMOVE_ALL_HOOKS: lambda h, _parts: _done(h.remove_all),
    RequestType.DISABLE_ALL_HOOKS: lambda h, _parts: _done(h.disable_all),
    RequestType.HOOKS_DUMP: lambda h, _parts: [h.dump()],
}


def _second(parts: Sequence[bytes]) -> bytes:
    if len(parts) != 2:
        raise _Refused("must be 2 parts message")
    return parts[1]


def _json_value(value: Any) -> Any:
    """A value as JSON holds it (what BehaviorTree.CPP exports a blackboard entry as)."""
    encoded = encode_value(value)
    try:
        json.dumps(encoded)
    except (TypeError, ValueError):
        return repr(value)
    return encoded
