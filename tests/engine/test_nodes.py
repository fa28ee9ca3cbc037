"""The node lifecycle: tick, latching, reset and halt (paper section III-B)."""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, with_children

from engine.composites import Sequence
from engine.node import Node
from engine.status import FAILURE, IDLE, RUNNING, SUCCESS, Status


def test_status_finished_only_for_success_and_failure() -> None:
    assert [s.finished for s in Status] == [False, False, True, True, False]
    assert Status("SUCCESS") is SUCCESS


@pytest.mark.parametrize("final", [SUCCESS, FAILURE])
def test_a_finished_node_is_latched_until_reset(ctx: Any, final: Status) -> None:
    node = ScriptedLeaf(ctx, "a", RUNNING, final, SUCCESS if final is FAILURE else FAILURE)
    assert node.tick() is RUNNING
    assert node.tick() is final
    for _ in range(3):
        assert node.tick() is final
    assert node.updates == 2  # latched: not evaluated again
    node.reset()
    assert node.status is IDLE
    assert node.tick() is not final  # evaluated again after the reset
    assert node.updates == 3


def test_status_sink_sees_each_change_once(ctx: Any) -> None:
    node = ScriptedLeaf(ctx, "a", RUNNING, RUNNING, SUCCESS)
    for _ in range(5):
        node.tick()
    node.reset()
    assert ctx.changes == [
        ("a", IDLE, RUNNING),
        ("a", RUNNING, SUCCESS),
        ("a", SUCCESS, IDLE),
    ]


def test_reset_of_an_idle_node_does_nothing(ctx: Any) -> None:
    node = ScriptedLeaf(ctx, "a")
    node.reset()
    assert (node.resets, node.halts, ctx.changes) == (0, 0, [])


def test_reset_halts_a_running_node_exactly_once(ctx: Any) -> None:
    node = ScriptedLeaf(ctx, "a", RUNNING)
    node.tick()
    node.reset()
    node.reset()
    node.halt()  # halt is reset: idempotent
    assert (node.halts, node.resets) == (1, 1)


def test_reset_of_a_finished_node_does_not_halt_it(ctx: Any) -> None:
    node = ScriptedLeaf(ctx, "a", SUCCESS)
    node.tick()
    node.reset()
    assert (node.halts, node.resets) == (0, 1)


def test_reset_clears_the_whole_subtree(ctx: Any) -> None:
    done = ScriptedLeaf(ctx, "done", SUCCESS)
    running = ScriptedLeaf(ctx, "running", RUNNING)
    inner = with_children(Sequence(ctx, "inner"), [done, running])
    top = with_children(Sequence(ctx, "top"), [inner])
    assert top.tick() is RUNNING
    top.reset()
    assert [n.status for n in top.iterate()] == [IDLE] * 4
    assert (done.halts, running.halts) == (0, 1)
    assert top.tick() is RUNNING
    assert (done.updates, running.updates) == (2, 2)  # evaluated again from the start


def test_reset_clears_the_message(ctx: Any) -> None:
    class Failing(Node):
        def update(self) -> Status:
            return self.fail("no cup")

    node = Failing(ctx, "f")
    assert node.tick() is FAILURE
    assert node.message == "no cup"
    node.reset()
    assert node.message == ""


def test_a_halt_that_raises_is_logged_and_the_reset_completes(ctx: Any) -> None:
    class BadHalt(ScriptedLeaf):
        def on_halt(self) -> None:
            raise RuntimeError("motor bus down")

    bad = BadHalt(ctx, "bad", RUNNING)
    seq = with_children(Sequence(ctx, "seq"), [bad])
    seq.tick()
    seq.reset()
    assert bad.status is IDLE and seq.status is IDLE
    assert ctx.logs == [("bad", "error while halting: RuntimeError: motor bus down")]


def test_update_is_required(ctx: Any) -> None:
    with pytest.raises(NotImplementedError, match="must implement update"):
        Node(ctx, "n").tick()


def test_iterate_is_depth_first_in_tick_order(ctx: Any) -> None:
    a, b, c = (ScriptedLeaf(ctx, x) for x in "abc")
    inner = with_children(Sequence(ctx, "inner"), [a, b])
    top = with_children(Sequence(ctx, "top"), [inner, c])
    assert [n.id for n in top.iterate()] == ["top", "inner", "a", "b", "c"]
    assert a.parent is inner and inner.parent is top
    assert repr(a) == "<ScriptedLeaf 'a' IDLE>"
