"""EventPump: executor events from any thread, coalesced per drain."""

from __future__ import annotations

import threading

from engine.events import BlackboardWritten, LogMessage, RunFinished, RunStarted, StatusChanged
from engine.status import Status
from instructor_app.runtime.pump import EventPump


def status(node: str, new: Status, message: str = "") -> StatusChanged:
    return StatusChanged(1, node, Status.IDLE, new, message, 0.0)


def test_the_newest_status_per_node_wins_but_failures_are_kept() -> None:
    pump = EventPump()
    pump.put(RunStarted(0.0, "plan"))
    pump.put(status("a", Status.RUNNING))
    pump.put(status("a", Status.FAILURE, "no cup"))
    pump.put(status("a", Status.IDLE))
    pump.put(status("b", Status.SUCCESS))
    pump.put(BlackboardWritten(1, "X", 1, "a", 0.0))
    pump.put(BlackboardWritten(2, "X", 2, "a", 0.0))
    pump.put(LogMessage(2, "b", "hello", 0.0))
    batch = pump.drain()
    assert batch.started
    assert batch.statuses == {"a": Status.IDLE, "b": Status.SUCCESS}
    assert batch.failures == [("a", "no cup", "")]
    assert batch.writes == {"X": 2} and batch.logs == [("b", "hello")]
    assert batch.finished is None
    assert pump.drain().empty


def test_events_from_another_thread_all_arrive() -> None:
    pump = EventPump()

    def produce() -> None:
        for i in range(10_000):
            pump.put(BlackboardWritten(i, f"K{i % 7}", i, "n", 0.0))
        pump.put(RunFinished(10_000, Status.SUCCESS, "finished", "", 0.0))

    thread = threading.Thread(target=produce)
    thread.start()
    seen: dict[str, int] = {}
    finished = None
    while finished is None:
        batch = pump.drain()
        seen.update(batch.writes)
        finished = batch.finished
    thread.join()
    assert finished.status is Status.SUCCESS
    assert seen == {f"K{k}": max(i for i in range(10_000) if i % 7 == k) for k in range(7)}
