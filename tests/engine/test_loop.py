"""BehaviorTree.CPP's LoopInt / LoopDouble / LoopBool / LoopString as our Loop, on the cases
of its tests/gtest_loop.cpp: static and blackboard queues, the empty queue, a failing child,
a restart after completion; and the Loop in plans and XML.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, logic, plan, with_children

from capabilities.base import CapabilityRegistry
from engine.btcpp import export_xml, import_xml
from engine.build import build_tree
from engine.files import dump_plan
from engine.leaves import ScriptLeaf
from engine.node import Node
from engine.queue_loop import Loop, parse_queue
from engine.spec import NodeKind
from engine.status import FAILURE, RUNNING, SKIPPED, SUCCESS, Status
from engine.validation import ERROR, validate_plan


def recorder(ctx: Any) -> Node:
    """A child that appends the loop's value to ``seen``."""
    return ScriptLeaf(ctx, "rec", "", "seen := seen .. val .. ';'")


def run(node: Node, ticks: int = 20) -> tuple[list[Status], Status]:
    statuses = []
    for _ in range(ticks):
        status = node.tick()
        statuses.append(status)
        if status is not RUNNING:
            break
    return statuses, statuses[-1]


@pytest.mark.parametrize(
    ("of", "queue", "seen"),
    [
        ("int", "1;2;3;4;5", "1;2;3;4;5;"),
        ("double", "1.5;-2.25", "1.500000;-2.250000;"),
        ("bool", "true;false;1", "true;false;true;"),
        ("string", "hello;world", "hello;world;"),
    ],
)
def test_a_static_queue_runs_the_child_once_per_value(
    ctx: Any, of: str, queue: str, seen: str
) -> None:
    ctx.blackboard.set("seen", "")
    node = with_children(Loop(ctx, "l", "", queue, "{val}", of), [recorder(ctx)])
    statuses, last = run(node)
    assert last is SUCCESS and len(statuses) == len(queue.split(";")) + 1
    assert ctx.blackboard.get("seen") == seen


@pytest.mark.parametrize("if_empty", [SUCCESS, FAILURE, SKIPPED])
def test_an_empty_queue_gives_if_empty_without_ticking_the_child(
    ctx: Any, if_empty: Status
) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS)
    node = with_children(Loop(ctx, "l", "", "{q}", "{val}", "int", if_empty), [child])
    assert node.tick() is if_empty and child.updates == 0


def test_a_failing_child_stops_the_loop(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", SUCCESS, FAILURE)
    node = with_children(Loop(ctx, "l", "", "1;2;3", "{val}", "int"), [child])
    assert run(node) == ([RUNNING, FAILURE], FAILURE)
    assert ctx.blackboard.get("val") == 2


def test_a_running_child_keeps_its_value(ctx: Any) -> None:
    child = ScriptedLeaf(ctx, "c", RUNNING, SUCCESS)
    node = with_children(Loop(ctx, "l", "", "7;8", "{val}", "int"), [child])
    assert node.tick() is RUNNING and ctx.blackboard.get("val") == 7
    assert node.tick() is RUNNING and ctx.blackboard.get("val") == 7  # child finished now
    assert node.tick() is RUNNING and ctx.blackboard.get("val") == 8


@pytest.mark.parametrize("held", ["4;5", [4, 5]])
def test_a_queue_from_the_blackboard_a_text_or_a_list(ctx: Any, held: Any) -> None:
    ctx.blackboard.set("q", held)
    ctx.blackboard.set("seen", "")
    node = with_children(Loop(ctx, "l", "", "{q}", "{val}", "int"), [recorder(ctx)])
    assert run(node)[1] is SUCCESS and ctx.blackboard.get("seen") == "4;5;"
    assert ctx.blackboard.get("q") == held  # read, never consumed


def test_the_loop_starts_over_after_a_reset(ctx: Any) -> None:
    ctx.blackboard.set("seen", "")
    node = with_children(Loop(ctx, "l", "", "1;2", "{val}", "int"), [recorder(ctx)])
    run(node)
    node.reset()
    assert run(node)[1] is SUCCESS and ctx.blackboard.get("seen") == "1;2;1;2;"


def test_queue_texts_convert_as_btcpp_does() -> None:
    assert parse_queue("1;-2", "int") == [1, -2]
    assert parse_queue("0.5;3", "double") == [0.5, 3.0]
    assert parse_queue("true;FALSE;0", "bool") == [True, False, False]
    assert parse_queue("a b;c", "string") == ["a b", "c"] and parse_queue("", "int") == []
    for text, of in [("1.5", "int"), ("yes", "bool"), ("x", "double")]:
        with pytest.raises(ValueError):
            parse_queue(text, of)


LOOP_XML = """<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="total := 0"/>
      <LoopInt queue="1;2;3" value="{n}"><Script code="total += n"/></LoopInt>
      <LoopString queue="{words}" value="{w}" if_empty="SKIPPED"><AlwaysFailure/></LoopString>
      <ScriptCondition code="total == 6"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_loops_from_xml_validate_run_and_go_back(registry: CapabilityRegistry) -> None:
    spec = import_xml(LOOP_XML, "loop.xml")
    loops = [node for _, node in spec.walk() if node.kind is NodeKind.LOOP]
    assert [n.params.get("type") is not None for n in loops] == [True, False]  # string: default
    assert [p for p in validate_plan(spec, registry) if p.severity == ERROR] == []
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(max_ticks=20) is SUCCESS
    assert tree.blackboard.get("total") == 6
    written = export_xml(spec, {})
    assert "<LoopInt " in written and "<LoopString " in written and " type=" not in written
    assert dump_plan(import_xml(written, "again.xml")) == dump_plan(spec)


def test_validation_of_a_loop(registry: CapabilityRegistry) -> None:
    child = logic(NodeKind.ALWAYS_SUCCESS)
    spec = plan(logic(NodeKind.LOOP, child, queue="1;x", value="n", type="int"))
    messages = [p.message for p in validate_plan(spec, registry) if p.severity == ERROR]
    assert any("as {key}, not 'n'" in m for m in messages)
    assert any("must hold int values" in m for m in messages)
