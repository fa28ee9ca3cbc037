"""Synthetic run records: a plan's nodes changing status at random, for the timeline's bench
and tests (a record of 100,000+ transitions takes a real run minutes; this takes a second).
"""

from __future__ import annotations

import json
import random
from pathlib import Path

from engine.spec import PlanSpec
from engine.status import Status
from engine.trace import TraceRecorder

__all__ = ["write_synthetic_record"]

_NEXT = {
    Status.IDLE: (Status.RUNNING, Status.SUCCESS, Status.FAILURE),
    Status.RUNNING: (Status.SUCCESS, Status.SUCCESS, Status.FAILURE, Status.IDLE),
    Status.SUCCESS: (Status.IDLE, Status.RUNNING),
    Status.FAILURE: (Status.IDLE, Status.RUNNING),
}


def write_synthetic_record(path: Path, plan: PlanSpec, transitions: int, seed: int = 1) -> Path:
    """Write a record of ``plan`` with ``transitions`` status changes of random nodes, a tick
    every 10 ms (several changes a tick), a blackboard write every 50 transitions and the
    joints every 100 ms; returns ``path``.
    """
    TraceRecorder(path, plan).close()  # the header, as a run writes it
    rnd = random.Random(seed)
    ids = [node.id for _, node in plan.walk()]
    state = dict.fromkeys(ids, Status.IDLE)
    now, tick, next_joints = 1000.0, 1, 1000.0
    lines = [json.dumps({"event": "started", "plan": plan.name, "time": now})]
    for index in range(transitions):
        if rnd.random() < 0.3:
            tick += 1
            now += 0.01
        node = rnd.choice(ids)
        old = state[node]
        new = state[node] = rnd.choice(_NEXT[old])
        record: dict[str, object] = {"event": "status", "tick": tick, "node": node}
        record |= {"old": old.value, "new": new.value}
        if new is Status.FAILURE:
            record |= {"message": f"failure {index}", "error": "failed"}
        lines.append(json.dumps(record | {"time": now}))
        if index % 50 == 0:
            write = {"event": "write", "tick": tick, "key": f"N{index % 7}", "value": index}
            lines.append(json.dumps(write | {"node": node, "time": now}))
        if now >= next_joints:
            q = [round(0.1 * a + 0.001 * tick, 6) for a in range(6)]
            lines.append(json.dumps({"event": "joints", "q": q, "time": now}))
            next_joints += 0.1
    lines.append(
        json.dumps(
            {"event": "finished", "tick": tick, "status": "SUCCESS", "reason": "finished"}
            | {"message": "", "time": now}
        )
    )
    with path.open("a", encoding="utf-8") as out:
        out.write("\n".join(lines) + "\n")
    return path
