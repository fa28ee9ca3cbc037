"""Groot2's breakpoints (BehaviorTree.CPP's hooks: HOOK_INSERT, HOOK_REMOVE,
BREAKPOINT_REACHED, BREAKPOINT_UNLOCK, REMOVE_ALL_HOOKS, DISABLE_ALL_HOOKS, HOOKS_DUMP) served
on the engine's debugger, a run paused at them, and announced on the publisher's PUB socket.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Any

import zmq

from capabilities.base import CapabilityRegistry
from capabilities.debug import capability as debug_capability
from capabilities.groot2.hooks import POST, PRE, Groot2Hooks
from capabilities.groot2.protocol import Groot2Monitor, RequestHeader, RequestType
from capabilities.groot2.publisher import Groot2Publisher
from engine.btcpp.runtime import loaded_tree
from engine.build import build_tree
from engine.debugger import Debugger
from engine.events import Event, RunPaused, StatusChanged
from engine.executor import Executor, ExecutorState
from engine.files import load_plan
from engine.status import FAILURE, SUCCESS
from resources import resource_path

# sequence.costar.json: steps (uid 1): one (2, succeeds), two (3, runs a tick), three (4)
TWO, THREE = 3, 4


def _wait(what: Callable[[], bool], timeout: float = 10.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if what():
            return True
        time.sleep(0.005)
    return what()


class _Run:
    """The example run, its monitor with hooks on its executor's debugger."""

    def __init__(self) -> None:
        plan = load_plan(str(resource_path("examples", "nodes", "sequence.costar.json")))
        registry = CapabilityRegistry([debug_capability()])
        self.loaded = loaded_tree(plan, {m.id: m for m in registry.manifests()})
        self.tree = build_tree(plan, registry)
        self.monitor = Groot2Monitor(self.loaded, self.tree.blackboard.snapshot())
        self.events: list[Event] = []
        self.executor = Executor(self.tree, 200.0, [self.monitor, self.events.append])
        self.monitor.hooks = Groot2Hooks(
            self.loaded.uids, self.executor.debugger, self.executor.resume
        )
        self.node = {uid: node_id for node_id, uid in self.loaded.uids.items()}

    def ask(self, kind: RequestType, body: dict[str, Any] | None = None) -> list[bytes]:
        parts = [RequestHeader.new(kind).encode()]
        if body is not None:
            parts.append(json.dumps(body).encode())
        reply = self.monitor.handle(parts)
        return reply if reply[0] == b"error" else reply[1:]

    def paused(self) -> RunPaused:
        assert _wait(lambda: any(isinstance(e, RunPaused) for e in self.events))
        return next(e for e in self.events if isinstance(e, RunPaused))


def _hook(uid: int, position: int = PRE, **more: Any) -> dict[str, Any]:
    return {
        "enabled": True,
        "uid": uid,
        "mode": 0,
        "once": False,
        "desired_status": "SKIPPED",
        "position": position,
        **more,
    }


def _unlock(uid: int, status: str, position: int = PRE, remove: bool = False) -> dict[str, Any]:
    return {"uid": uid, "desired_status": status, "position": position, "remove_when_done": remove}


def test_hooks_are_inserted_dumped_and_removed_as_debugger_breakpoints() -> None:
    run = _Run()
    debugger: Debugger = run.executor.debugger
    assert run.ask(RequestType.HOOK_INSERT, _hook(TWO)) == []
    assert run.ask(RequestType.HOOK_INSERT, _hook(TWO, POST, once=True)) == []
    breakpoint = debugger.breakpoints[run.node[TWO]]
    assert breakpoint.before and breakpoint.after
    (dump,) = run.ask(RequestType.HOOKS_DUMP)
    assert json.loads(dump) == [_hook(TWO), _hook(TWO, POST, once=True)]
    assert run.ask(RequestType.HOOK_REMOVE, {"uid": TWO, "position": PRE}) == []
    assert not debugger.breakpoints[run.node[TWO]].before
    assert run.ask(RequestType.HOOK_REMOVE, {"uid": TWO, "position": PRE}) == [
        b"error",
        b"Node ID not found",
    ]
    assert run.ask(RequestType.DISABLE_ALL_HOOKS) == []
    assert debugger.breakpoints == {}
    assert json.loads(run.ask(RequestType.HOOKS_DUMP)[0])[0]["enabled"] is False
    assert run.ask(RequestType.REMOVE_ALL_HOOKS) == []
    assert run.ask(RequestType.HOOKS_DUMP) == [b"[]"]


def test_bad_hooks_get_the_error_reply() -> None:
    run = _Run()
    replace = run.ask(RequestType.HOOK_INSERT, _hook(TWO, mode=1))
    assert replace[0] == b"error" and b"REPLACE" in replace[1]
    assert run.ask(RequestType.HOOK_INSERT, _hook(99)) == [b"error", b"Node ID not found"]
    assert run.ask(RequestType.BREAKPOINT_UNLOCK, _unlock(TWO, "SUCCESS"))[0] == b"error"
    assert run.monitor.handle([RequestHeader.new(RequestType.HOOK_INSERT).encode()]) == [
        b"error",
        b"must be 2 parts message",
    ]
    assert run.ask(RequestType.HOOK_INSERT, {"uid": TWO})[0] == b"error"
    assert run.executor.debugger.breakpoints == {}


def test_a_run_pauses_at_a_hook_and_an_unlock_lets_the_node_run() -> None:
    run = _Run()
    run.ask(RequestType.HOOK_INSERT, _hook(TWO))
    run.executor.start()
    hit = run.paused()
    assert hit.node_id == run.node[TWO] and run.executor.state is ExecutorState.PAUSED
    (header, uid) = run.monitor.reached_breakpoints()
    assert RequestHeader.decode(header).type == RequestType.BREAKPOINT_REACHED
    assert uid == str(TWO).encode()
    assert run.ask(RequestType.BREAKPOINT_UNLOCK, _unlock(TWO, "SKIPPED", remove=True)) == []
    result = run.executor.wait(10.0)
    assert result is not None and result.status is SUCCESS
    assert run.ask(RequestType.HOOKS_DUMP) == [b"[]"]  # removed when done


def test_an_unlock_with_failure_gives_the_node_that_result_without_running_it() -> None:
    run = _Run()
    run.ask(RequestType.HOOK_INSERT, _hook(TWO))
    run.executor.start()
    run.paused()
    run.ask(RequestType.BREAKPOINT_UNLOCK, _unlock(TWO, "FAILURE"))
    result = run.executor.wait(10.0)
    assert result is not None and result.status is FAILURE
    two = [e for e in run.events if isinstance(e, StatusChanged) and e.node_id == run.node[TWO]]
    assert [e.new for e in two] == [FAILURE]  # never RUNNING: not run
    assert not any(
        isinstance(e, StatusChanged) and e.node_id == run.node[THREE] for e in run.events
    )


def test_disabling_the_hooks_frees_a_paused_run() -> None:
    run = _Run()
    run.ask(RequestType.HOOK_INSERT, _hook(THREE, POST))
    run.executor.start()
    assert run.paused().node_id == run.node[THREE]
    run.ask(RequestType.DISABLE_ALL_HOOKS)
    result = run.executor.wait(10.0)
    assert result is not None and result.status is SUCCESS


def test_the_publisher_announces_a_reached_breakpoint_on_its_pub_socket() -> None:
    from groot2_client import free_port_pair

    run = _Run()
    port = free_port_pair()
    with Groot2Publisher(run.monitor, port) as publisher:
        context = zmq.Context()
        subscriber = context.socket(zmq.SUB)
        subscriber.setsockopt(zmq.LINGER, 0)
        subscriber.setsockopt(zmq.SUBSCRIBE, b"")
        subscriber.connect(f"tcp://127.0.0.1:{port + 1}")
        client = context.socket(zmq.REQ)
        client.setsockopt(zmq.LINGER, 0)
        client.setsockopt(zmq.RCVTIMEO, 10000)
        client.connect(f"tcp://{publisher.address}")
        try:
            time.sleep(0.2)  # the subscription reaches the PUB socket
            client.send_multipart(
                [
                    RequestHeader.new(RequestType.HOOK_INSERT).encode(),
                    json.dumps(_hook(TWO)).encode(),
                ]
            )
            assert len(client.recv_multipart()) == 1  # the header alone
            run.executor.start()
            assert subscriber.poll(10000), "no BREAKPOINT_REACHED"
            header, uid = subscriber.recv_multipart()
            assert RequestHeader.decode(header).type == RequestType.BREAKPOINT_REACHED
            assert uid == str(TWO).encode()
            unlock = _unlock(TWO, "SKIPPED")
            client.send_multipart(
                [
                    RequestHeader.new(RequestType.BREAKPOINT_UNLOCK).encode(),
                    json.dumps(unlock).encode(),
                ]
            )
            assert len(client.recv_multipart()) == 1
            result = run.executor.wait(10.0)
            assert result is not None and result.status is SUCCESS
        finally:
            subscriber.close(0)
            client.close(0)
            context.term()
            run.executor.stop()
