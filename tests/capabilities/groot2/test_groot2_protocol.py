"""The Groot2 protocol's bytes (BehaviorTree.CPP's groot2_protocol.h), without sockets."""

from __future__ import annotations

import struct
import uuid
import xml.etree.ElementTree as ET

import msgpack
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.debug import capability as debug_capability
from capabilities.groot2.protocol import (
    Groot2Monitor,
    ProtocolError,
    ReplyHeader,
    RequestHeader,
    RequestType,
    decode_status,
    decode_transitions,
    encode_status,
    encode_transitions,
    status_code,
)
from engine.btcpp.runtime import LoadedTree, loaded_tree
from engine.events import BlackboardWritten, StatusChanged
from engine.files import load_plan
from engine.status import Status
from resources import resource_path


def _loaded() -> LoadedTree:
    plan = load_plan(str(resource_path("examples", "nodes", "subtree.costar.json")))
    registry = CapabilityRegistry([debug_capability()])
    return loaded_tree(plan, {m.id: m for m in registry.manifests()})


def _ask(monitor: Groot2Monitor, kind: RequestType, *more: bytes) -> tuple[ReplyHeader, list]:
    request = RequestHeader.new(kind)
    reply = monitor.handle([request.encode(), *more])
    header = ReplyHeader.decode(reply[0])
    assert header.request == request
    return header, reply[1:]


def test_the_request_header_is_protocol_type_and_a_little_endian_id() -> None:
    header = RequestHeader(RequestType.STATUS, 0x01020304)
    data = header.encode()
    assert data == bytes([2, ord("S"), 4, 3, 2, 1])
    assert RequestHeader.decode(data) == header
    fresh = RequestHeader.new(RequestType.FULLTREE)
    assert RequestHeader.decode(fresh.encode()) == fresh
    with pytest.raises(ProtocolError):
        RequestHeader.decode(data + b"x")


def test_the_reply_header_adds_the_16_byte_tree_id() -> None:
    tree_id = uuid.uuid4().bytes
    header = ReplyHeader(RequestHeader(RequestType.FULLTREE, 7), tree_id)
    data = header.encode()
    assert len(data) == 22 and data[6:] == tree_id
    assert ReplyHeader.decode(data) == header


def test_status_payload_is_uid_as_uint16_and_a_status_byte() -> None:
    payload = encode_status([(1, 1), (300, 2)])
    assert payload == struct.pack("<HBHB", 1, 1, 300, 2)
    assert decode_status(payload) == [(1, 1), (300, 2)]


def test_status_codes_are_btcpp_and_a_reset_tells_what_it_was() -> None:
    assert status_code(Status.IDLE, Status.RUNNING) == 1
    assert status_code(Status.RUNNING, Status.SUCCESS) == 2
    assert status_code(Status.RUNNING, Status.FAILURE) == 3
    assert status_code(Status.SUCCESS, Status.IDLE) == 12
    assert status_code(Status.RUNNING, Status.IDLE) == 11
    assert status_code(Status.IDLE, Status.SKIPPED) == 4


def test_transitions_are_nine_bytes_each() -> None:
    payload = encode_transitions([(1_500_000, 3, 1), (2**40, 4, 2)])
    assert len(payload) == 18
    assert decode_transitions(payload) == [(1_500_000, 3, 1), (2**40, 4, 2)]


def test_full_tree_is_the_loaded_xml_under_one_tree_id() -> None:
    monitor = Groot2Monitor(_loaded())
    first, (xml,) = _ask(monitor, RequestType.FULLTREE)
    root = ET.fromstring(xml)
    assert all(n.get("_uid") for t in root.iter("BehaviorTree") for n in t.iter() if n is not t)
    again, _ = _ask(monitor, RequestType.STATUS)
    assert again.tree_id == first.tree_id
    assert uuid.UUID(bytes=first.tree_id).version == 4


def test_status_lists_every_node_and_follows_the_run() -> None:
    loaded = _loaded()
    monitor = Groot2Monitor(loaded)
    _, (payload,) = _ask(monitor, RequestType.STATUS)
    assert [uid for uid, _ in decode_status(payload)] == loaded.order
    assert {code for _, code in decode_status(payload)} == {0}
    left = next(i for i in loaded.instances if i.path == "left")
    inner = next(rid for rid, uid in loaded.uids.items() if uid == left.uids[0])
    monitor(StatusChanged(1, inner, Status.IDLE, Status.RUNNING, "", 0.0))
    monitor(StatusChanged(1, "root", Status.IDLE, Status.RUNNING, "", 0.0))  # not a node there
    _, (payload,) = _ask(monitor, RequestType.STATUS)
    assert dict(decode_status(payload))[left.uids[0]] == 1
    monitor(StatusChanged(2, inner, Status.RUNNING, Status.IDLE, "", 0.0))
    assert monitor.statuses()[left.uids[0]] == 11


def test_blackboard_dump_is_messagepack_per_instance() -> None:
    loaded = _loaded()
    monitor = Groot2Monitor(loaded, {"LEFT": 1.0})
    left = next(i for i in loaded.instances if i.path == "left")
    monitor(BlackboardWritten(1, f"{left.names}GOAL", "here", "x", 0.0))
    _, (packed,) = _ask(monitor, RequestType.BLACKBOARD, b"Subtree_instances;left")
    assert msgpack.unpackb(packed) == {"Subtree_instances": {"LEFT": 1.0}, "left": {"GOAL": "here"}}
    _, reply = _ask(monitor, RequestType.BLACKBOARD, b"nobody")
    assert msgpack.unpackb(reply[0]) == {}


def test_recording_gives_transitions_since_its_start() -> None:
    now = [100.0]
    loaded = _loaded()
    monitor = Groot2Monitor(loaded, clock=lambda: now[0], wall=lambda: 1_700_000_000.0)
    _, (started,) = _ask(monitor, RequestType.TOGGLE_RECORDING, b"start")
    assert started == b"1700000000000000"
    node = next(iter(loaded.uids))
    monitor(StatusChanged(1, node, Status.IDLE, Status.RUNNING, "", 100.25))
    monitor(StatusChanged(2, node, Status.RUNNING, Status.IDLE, "", 100.5))
    _, (payload,) = _ask(monitor, RequestType.GET_TRANSITIONS)
    assert decode_transitions(payload) == [(250_000, 1, 1), (500_000, 1, 0)]
    _, (payload,) = _ask(monitor, RequestType.GET_TRANSITIONS)
    assert payload == b""
    _ask(monitor, RequestType.TOGGLE_RECORDING, b"stop")
    monitor(StatusChanged(3, node, Status.IDLE, Status.RUNNING, "", 101.0))
    _, (payload,) = _ask(monitor, RequestType.GET_TRANSITIONS)
    assert payload == b""


def test_hooks_are_answered_as_none_and_refused_as_btcpp_refuses() -> None:
    monitor = Groot2Monitor(_loaded())
    _, (dump,) = _ask(monitor, RequestType.HOOKS_DUMP)
    assert dump == b"[]"
    _, rest = _ask(monitor, RequestType.REMOVE_ALL_HOOKS)
    assert rest == []
    request = RequestHeader.new(RequestType.HOOK_INSERT).encode()
    reply = monitor.handle([request, b'{"uid": 1}'])
    assert reply[0] == b"error" and b"not supported" in reply[1]


def test_bad_requests_get_the_error_reply() -> None:
    monitor = Groot2Monitor(_loaded())
    assert monitor.handle([b"abc"]) == [b"error", b"wrong request header"]
    assert monitor.handle([RequestHeader(ord("?"), 1).encode()])[0] == b"error"
    blackboard = RequestHeader.new(RequestType.BLACKBOARD).encode()
    assert monitor.handle([blackboard]) == [b"error", b"must be 2 parts message"]
