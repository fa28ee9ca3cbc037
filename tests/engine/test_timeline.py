"""The timeline of a run record: statuses, values, joints and figures at any moment, checked
against a naive replay of the record, and fast for a record of 100,000 transitions.
"""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any

import pytest

from bench._records import write_synthetic_record
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.timeline import Timeline
from engine.trace import read_trace


def _plan(groups: int = 20, leaves: int = 9) -> PlanSpec:
    """A sequence of selectors of debug leaves: ``groups * (leaves + 1) + 1`` nodes."""
    children = [
        NodeSpec(
            NodeKind.SELECTOR,
            name=f"group {g}",
            children=[
                NodeSpec(NodeKind.OPERATION, name=f"leaf {g}.{i}", op="debug.succeed")
                for i in range(leaves)
            ],
        )
        for g in range(groups)
    ]
    return PlanSpec(NodeSpec(NodeKind.SEQUENCE, name="top", children=children), "wide")


def _replayed(events: list[dict[str, Any]], start: float, t: float) -> dict[str, Any]:
    """Statuses, values and joints at ``t``, by going through the whole record."""
    statuses: dict[str, str] = {}
    values: dict[str, Any] = {}
    joints = None
    for event in events:
        if float(event.get("time", start)) - start > t:
            break
        if event["event"] == "status":
            statuses[event["node"]] = event["new"]
        elif event["event"] == "write":
            values[event["key"]] = event["value"]
        elif event["event"] == "joints":
            joints = tuple(event["q"])
    return {"statuses": statuses, "values": values, "joints": joints}


def test_every_query_of_a_100000_transition_record_matches_a_replay(tmp_path: Path) -> None:
    plan = _plan()
    path = write_synthetic_record(tmp_path / "big.trace.jsonl", plan, 100_000, seed=5)
    trace = read_trace(path)
    timeline = Timeline(trace, path.name)
    assert timeline.transitions == 100_000
    start = float(trace.events[0]["time"])
    moments = [0.0, 0.004, 1.0, 37.3333, timeline.duration / 2, timeline.duration - 0.01]
    moments += [timeline.times[i] for i in (255, 256, 257, 512, 99_999)]
    moments += [timeline.duration + 5.0]
    for t in moments:
        expected = _replayed(trace.events, start, t)
        statuses = timeline.statuses_at(t)
        shown = {n: s.value for n, s in statuses.items() if s is not Status.IDLE}
        assert shown == {n: s for n, s in expected["statuses"].items() if s != "IDLE"}, t
        running = [n for n, s in expected["statuses"].items() if s == "RUNNING"]
        assert sorted(timeline.running_at(t)) == sorted(running)
        assert {e.key: e.value for e in timeline.values_at(t)} == expected["values"]
        assert timeline.joints_at(t) == expected["joints"]


def test_figures_count_starts_results_ticks_and_time_running(tmp_path: Path) -> None:
    path = tmp_path / "small.trace.jsonl"
    lines = [
        '{"format":"costar-trace","format_version":1,"nodes":'
        '[{"id":"a","label":"top","kind":"sequence","path":"top"},'
        '{"id":"b","label":"grasp","kind":"debug.fail","path":"top/grasp"}]}',
        '{"event":"started","plan":"p","time":10.0}',
        '{"event":"status","tick":1,"node":"a","old":"IDLE","new":"RUNNING","time":10.0}',
        '{"event":"status","tick":1,"node":"b","old":"IDLE","new":"RUNNING","time":10.0}',
        '{"event":"status","tick":3,"node":"b","old":"RUNNING","new":"FAILURE",'
        '"message":"nothing between the fingers","error":"grasp_failed","time":10.5}',
        '{"event":"status","tick":3,"node":"a","old":"RUNNING","new":"FAILURE","time":10.5}',
        '{"event":"status","tick":4,"node":"b","old":"FAILURE","new":"SUCCESS","time":11.0}',
        '{"event":"joints","q":[1,2,3,4,5,6],"time":10.2}',
    ]
    path.write_text("\n".join(lines) + "\n")
    timeline = Timeline.load(path)
    grasp = timeline.figures("b")
    assert (grasp.starts, grasp.successes, grasp.failures, grasp.ticks) == (2, 1, 1, 4)
    assert abs(grasp.running_s - 0.5) < 1e-9
    assert timeline.figures("a").failures == 1
    assert [(m.node_id, m.tick, m.error, m.index) for m in timeline.failures] == [
        ("b", 3, "grasp_failed", 2)
    ]
    assert timeline.statuses_after(3) == {
        "root": Status.IDLE,
        "a": Status.RUNNING,
        "b": Status.FAILURE,
    }
    assert timeline.failure_near(0.45, 0.1) == timeline.failures[0]
    assert timeline.failure_near(0.2, 0.1) is None
    assert timeline.running_at(0.3) == ["a", "b"]
    failed = {"root": Status.IDLE, "a": Status.FAILURE, "b": Status.FAILURE}
    assert timeline.statuses_at(0.7) == failed
    assert timeline.joints_at(0.1) is None and timeline.joints_at(0.3) == (1, 2, 3, 4, 5, 6)
    assert timeline.plan() is None  # a record without the plan's document


def test_the_picture_of_a_moment_is_each_cameras_last_thumbnail_before_it(
    tmp_path: Path,
) -> None:
    path = tmp_path / "pictures.trace.jsonl"
    first, second, wrist = b"\xff\xd8first", b"\xff\xd8second", b"\xff\xd8wrist"
    b64 = {k: base64.b64encode(v).decode() for k, v in (("1", first), ("2", second), ("w", wrist))}
    lines = [
        '{"format":"costar-trace","format_version":1,"nodes":[]}',
        '{"event":"started","plan":"p","time":10.0}',
        f'{{"event":"thumbnail","camera":"shoulder","jpeg":"{b64["1"]}","time":10.2}}',
        f'{{"event":"thumbnail","camera":"wrist","jpeg":"{b64["w"]}","time":10.3}}',
        f'{{"event":"thumbnail","camera":"shoulder","jpeg":"{b64["2"]}","time":11.2}}',
        '{"event":"thumbnail","camera":"shoulder","jpeg":"not base64!","time":12.2}',
        '{"event":"finished","tick":3,"status":"SUCCESS","reason":"finished","message":"",'
        '"time":12.5}',
    ]
    path.write_text("\n".join(lines) + "\n")
    timeline = Timeline.load(path)
    assert timeline.cameras == ["shoulder", "wrist"]
    assert timeline.pictures_at(0.1) == {}
    assert timeline.pictures_at(0.25) == {"shoulder": first}
    assert timeline.pictures_at(1.5) == {"shoulder": second, "wrist": wrist}
    assert timeline.pictures_at(2.3) == {"wrist": wrist}  # a broken picture is left out
    assert timeline.picture_time("shoulder", 1.5) == pytest.approx(1.2)
    assert timeline.picture_time("wrist", 0.25) is None
