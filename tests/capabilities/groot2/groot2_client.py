"""A Groot2 client written from groot2_protocol.h, and free ports for a publisher (test helper)."""

from __future__ import annotations

import socket
import time
import xml.etree.ElementTree as ET

import zmq

from capabilities.groot2.protocol import ReplyHeader, RequestHeader, RequestType, decode_status


def free_port_pair() -> int:
    """A port that is free, with the next one free too (the publisher takes both)."""
    for _ in range(100):
        with socket.socket() as first:
            first.bind(("127.0.0.1", 0))
            port = int(first.getsockname()[1])
            if port >= 65535:
                continue
            with socket.socket() as second:
                try:
                    second.bind(("127.0.0.1", port + 1))
                except OSError:
                    continue
        return port
    raise RuntimeError("no two free ports in a row")


class Client:
    """Groot2's side: a REQ socket, one request at a time, each checked against its reply."""

    def __init__(self, port: int) -> None:
        self.context = zmq.Context()
        self.socket = self.context.socket(zmq.REQ)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.setsockopt(zmq.RCVTIMEO, 20_000)
        self.socket.connect(f"tcp://127.0.0.1:{port}")

    def ask(self, kind: RequestType) -> tuple[ReplyHeader, list[bytes]]:
        request = RequestHeader.new(kind)
        self.socket.send(request.encode())
        parts = self.socket.recv_multipart()
        header = ReplyHeader.decode(parts[0])
        assert header.request == request
        return header, parts[1:]

    def close(self) -> None:
        self.socket.close(0)
        self.context.term()

    def uids(self) -> tuple[bytes, dict[str, int]]:
        """FULLTREE: the tree id, and each node's ``_uid`` by its name (names unique here)."""
        header, (xml,) = self.ask(RequestType.FULLTREE)
        root = ET.fromstring(xml)
        found = {
            str(node.get("name") or node.get("_fullpath")): int(node.get("_uid", ""))
            for tree in root.iter("BehaviorTree")
            for node in tree.iter()
            if node is not tree
        }
        return header.tree_id, found

    def statuses_once(self, uid: int, code: int, timeout: float = 30.0) -> dict[int, int]:
        """STATUS, asked again until node ``uid`` has ``code`` (or ``timeout`` passed)."""
        deadline = time.monotonic() + timeout
        while True:
            _, (payload,) = self.ask(RequestType.STATUS)
            statuses = dict(decode_status(payload))
            if statuses.get(uid) == code or time.monotonic() > deadline:
                return statuses
