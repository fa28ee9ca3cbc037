"""SkipUnlessUpdated, WaitValueUpdate and WasEntryUpdated (BehaviorTree.CPP 4.10's
src/decorators/updated_decorator.cpp, src/actions/updated_action.cpp) and the blackboard's
sequence numbers they read; the plan cases are those of its tests/gtest_updates.cpp.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, with_children

from capabilities.base import CapabilityRegistry
from engine.blackboard import Blackboard
from engine.btcpp import import_xml
from engine.build import build_tree
from engine.entry_updates import SkipUnlessUpdated, WaitValueUpdate, WasEntryUpdated
from engine.status import FAILURE, RUNNING, SKIPPED, SUCCESS

# ---------------------------------------------------------------------- the blackboard


def test_each_write_counts_and_an_unset_starts_again() -> None:
    board = Blackboard()
    assert board.sequence("a") == 0
    board.set("a", 1, "n1")
    board.set("a", 1, "n2")  # the same value is a write all the same
    assert board.sequence("a") == 2
    entry = board.entry("a")
    assert entry is not None and entry.sequence == 2 and entry.writer == "n2"
    board.unset("a")
    assert board.sequence("a") == 0
    board.set("a", 5)
    assert board.sequence("a") == 1
    board.clear()
    assert board.sequence("a") == 0


# ---------------------------------------------------------------------- the nodes


def test_was_entry_updated_succeeds_once_per_write(ctx: Any) -> None:
    node = WasEntryUpdated(ctx, "w", "", "A")
    assert node.tick() is FAILURE  # no entry
    node.reset()
    ctx.blackboard.set("A", 1)
    assert node.tick() is SUCCESS
    node.reset()
    assert node.tick() is FAILURE
    node.reset()
    ctx.blackboard.set("A", 1)
    assert node.tick() is SUCCESS


def test_each_node_remembers_what_it_saw(ctx: Any) -> None:
    ctx.blackboard.set("A", 1)
    first, second = WasEntryUpdated(ctx, "a", "", "{A}"), WasEntryUpdated(ctx, "b", "", "A")
    assert first.tick() is SUCCESS and second.tick() is SUCCESS


def test_a_missing_entry_leaves_the_number_seen(ctx: Any) -> None:
    """Unset and written once again, the entry's number is the one seen: not updated (as
    BehaviorTree.CPP's, whose new entry counts from 0 again).
    """
    board = ctx.blackboard
    node = WasEntryUpdated(ctx, "w", "", "A")
    board.set("A", 1)
    assert node.tick() is SUCCESS
    board.unset("A")
    node.reset()
    assert node.tick() is FAILURE
    board.set("A", 2)
    node.reset()
    assert node.tick() is FAILURE


def test_an_entry_in_a_scope_and_at_the_top(ctx: Any) -> None:
    scoped = WasEntryUpdated(ctx, "w", "", "A", key=lambda name: f"inner/{name}")
    top = WasEntryUpdated(ctx, "t", "", "@A", key=lambda name: f"inner/{name}")
    ctx.blackboard.set("A", 1)
    assert scoped.tick() is FAILURE and top.tick() is SUCCESS
    ctx.blackboard.set("inner/A", 1)
    scoped.reset()
    assert scoped.tick() is SUCCESS


def test_an_empty_entry_port_is_refused(ctx: Any) -> None:
    with pytest.raises(ValueError):
        WasEntryUpdated(ctx, "w", "", "{ }")


def test_skip_unless_updated_skips_until_a_write(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS, SUCCESS)
    node = with_children(SkipUnlessUpdated(ctx, "s", "", "A"), [child])
    assert node.tick() is SKIPPED and child.updates == 0
    node.reset()
    ctx.blackboard.set("A", 1)
    assert node.tick() is SUCCESS and child.updates == 1
    node.reset()
    assert node.tick() is SKIPPED and child.updates == 1


def test_a_running_child_goes_on_without_a_check(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING, RUNNING, SUCCESS)
    node = with_children(SkipUnlessUpdated(ctx, "s", "", "A"), [child])
    ctx.blackboard.set("A", 1)
    assert node.tick() is RUNNING
    assert node.tick() is RUNNING  # no write since: the child is ticked on all the same
    assert node.tick() is SUCCESS and child.updates == 3


def test_a_halt_forgets_the_running_child_not_the_number_seen(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING, RUNNING)
    node = with_children(SkipUnlessUpdated(ctx, "s", "", "A"), [child])
    ctx.blackboard.set("A", 1)
    assert node.tick() is RUNNING
    node.reset()
    assert child.status.value == "IDLE"
    assert node.tick() is SKIPPED and child.updates == 1


def test_wait_value_update_runs_until_the_entry_is_written(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS)
    node = with_children(WaitValueUpdate(ctx, "w", "", "{A}"), [child])
    assert node.tick() is RUNNING
    assert node.tick() is RUNNING and child.updates == 0
    ctx.blackboard.set("A", 1)
    assert node.tick() is SUCCESS and child.updates == 1


# ---------------------------------------------------------------------- tests/gtest_updates.cpp

_CHECK = """<BehaviorTree ID="Check">
  <Sequence>
    <Fallback><WasEntryUpdated entry="A"/><Script code="@tested_a += 1"/></Fallback>
    <SkipUnlessUpdated entry="A"><Script code="@tested_b += 1"/></SkipUnlessUpdated>
  </Sequence>
</BehaviorTree>"""


def _run(registry: CapabilityRegistry, main: str) -> tuple[int, int]:
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'{_CHECK}<BehaviorTree ID="Main"><Sequence>'
        '<Script code="tested_a := 0; tested_b := 0"/>'
        f"{main}</Sequence></BehaviorTree></root>"
    )
    tree = build_tree(import_xml(text, "updates.xml"), registry)
    assert tree.tick_until_done(max_ticks=20) is SUCCESS
    board = tree.blackboard
    return board.get("tested_a"), board.get("tested_b")


_SUB = '<SubTree ID="Check" _autoremap="true"/>'


@pytest.mark.parametrize(
    ("main", "counts"),
    [
        (_SUB, (1, 0)),  # NoEntry: the fallback runs, the child is skipped
        (f'<Script code="A:=1;B:=1"/>{_SUB}', (0, 1)),  # Initialized
        (f'<Script code="A:=1"/><Repeat num_cycles="2">{_SUB}</Repeat>', (1, 1)),  # UpdateOnce
        (  # UpdateTwice
            f'<Repeat num_cycles="2"><Sequence><Script code="A:=1"/>{_SUB}</Sequence></Repeat>',
            (0, 2),
        ),
    ],
    ids=["no_entry", "initialized", "update_once", "update_twice"],
)
def test_the_cases_of_gtest_updates(
    registry: CapabilityRegistry, main: str, counts: tuple[int, int]
) -> None:
    assert _run(registry, main) == counts
