"""Blackboard entries: who wrote each last, at which tick and when; set by the user while a
run is paused (checked against the entry's type, written by the engine between ticks).
"""

from __future__ import annotations

import pytest
from bt_fakes import Recorder, ScriptedLeaf, rooted, wait_until

from engine.blackboard import OPERATOR, Blackboard, BlackboardError
from engine.context import TreeContext
from engine.events import BlackboardWritten
from engine.executor import Executor
from engine.status import RUNNING
from engine.types import ParamType, Pose


def test_each_entry_keeps_its_last_writer_and_tick() -> None:
    ctx = TreeContext(Blackboard({"TARGET": ParamType.POSE}))
    board = ctx.blackboard
    board.set("TARGET", Pose(), "plan")
    ctx.tick_count = 3
    board.set("TARGET", Pose((0.4, 0.0, 0.3)), "find-target")
    entry = board.entry("TARGET")
    assert entry is not None
    assert (entry.writer, entry.tick, entry.ptype) == ("find-target", 3, ParamType.POSE)
    assert entry.value == Pose((0.4, 0.0, 0.3)) and entry.time > 0
    assert board.entry("NOTHING") is None
    assert [e.key for e in board.entries()] == ["TARGET"]
    board.unset("TARGET")
    assert board.entry("TARGET") is None and board.entries() == []


def test_a_value_of_another_type_is_refused_naming_the_entry_and_its_type() -> None:
    board = Blackboard({"TARGET": ParamType.POSE})
    with pytest.raises(BlackboardError, match=r"'TARGET' holds Pose, not float 2\.0"):
        board.check("TARGET", 2.0)
    board.check("ANYTHING", 2.0)  # undeclared: any value


def busy_tree() -> tuple[Executor, TreeContext]:
    ctx = TreeContext(Blackboard({"SPEED": ParamType.NUMBER}))
    ctx.blackboard.set("SPEED", 0.1, "plan")
    return Executor(rooted(ctx, ScriptedLeaf(ctx, "busy", RUNNING)), rate_hz=1000.0), ctx


def test_set_entry_while_paused_is_written_between_ticks_and_reported() -> None:
    executor, ctx = busy_tree()
    seen = Recorder()
    executor.add_listener(seen)
    executor.start(paused=True)
    executor.step()
    assert wait_until(lambda: ctx.tick_count == 1)
    executor.set_entry("SPEED", 0.25)
    assert wait_until(lambda: ctx.blackboard.get("SPEED") == 0.25)
    assert ctx.tick_count == 1  # written while paused, no tick for it
    entry = ctx.blackboard.entry("SPEED")
    assert entry is not None and (entry.writer, entry.tick) == (OPERATOR, 1)
    executor.stop()
    executor.wait(5.0)
    writes = [e for e in seen.events if isinstance(e, BlackboardWritten)]
    assert [(e.key, e.value, e.node_id, e.tick) for e in writes] == [("SPEED", 0.25, OPERATOR, 1)]


def test_set_entry_refuses_a_wrong_type_and_a_run_that_is_not_paused() -> None:
    executor, ctx = busy_tree()
    executor.start(paused=True)
    with pytest.raises(BlackboardError, match="'SPEED' holds Number, not str"):
        executor.set_entry("SPEED", "fast")
    executor.resume()
    with pytest.raises(RuntimeError, match="only while the run is paused"):
        executor.set_entry("SPEED", 0.3)
    executor.stop()
    executor.wait(5.0)
    assert ctx.blackboard.get("SPEED") == 0.1
