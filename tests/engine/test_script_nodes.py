"""Script and ScriptCondition as plan nodes: built, run in their scope, validated, and read
from and written to BehaviorTree.CPP v4 XML (BehaviorTree.CPP's Script / ScriptCondition).
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import ScriptedLeaf, logic, op, plan

from capabilities.base import CapabilityRegistry
from engine.btcpp import export_xml, import_xml
from engine.build import BuildError, build_tree
from engine.composites import ReactiveSequence
from engine.error_types import ErrorType
from engine.files import dump_plan, loads_plan
from engine.instances import Scope
from engine.leaves import ScriptLeaf
from engine.script import ScriptSyntaxError
from engine.spec import NodeKind, PlanSpec
from engine.status import FAILURE, RUNNING, SUCCESS
from engine.validation import ERROR, WARNING, validate_plan


def script(code: str, name: str = "") -> Any:
    return logic(NodeKind.SCRIPT, name=name, code=code)


def condition(code: str, name: str = "") -> Any:
    return logic(NodeKind.SCRIPT_CONDITION, name=name, code=code)


def test_a_script_writes_and_a_condition_answers(ctx: Any) -> None:
    write = ScriptLeaf(ctx, "s", "set up", "count := 2; label := 'tray ' .. count")
    check = ScriptLeaf(ctx, "c", "", "count >= 2 && label == 'tray 2'", condition=True)
    assert write.tick() is SUCCESS
    assert ctx.blackboard.snapshot() == {"count": 2, "label": "tray 2"}
    assert check.tick() is SUCCESS and check.is_condition and not write.is_condition
    assert check.name == "script_condition" and write.name == "set up"
    ctx.blackboard.set("count", 1)
    check.reset()
    assert check.tick() is FAILURE and check.message == "false"


def test_a_failing_script_fails_its_node_as_invalid_input(ctx: Any) -> None:
    node = ScriptLeaf(ctx, "s", "", "a := 1;\nb = a + 1")
    assert node.tick() is FAILURE
    assert node.error is ErrorType.INVALID_INPUT
    assert node.message.startswith("script line 2, column 3: the entry 'b' does not exist")
    assert ctx.blackboard.get("a") == 1


def test_a_condition_whose_value_is_not_true_or_false_fails_with_the_reason(ctx: Any) -> None:
    node = ScriptLeaf(ctx, "c", "", "'perhaps'", condition=True)
    assert node.tick() is FAILURE
    assert "expected true or false" in node.message and node.error is ErrorType.INVALID_INPUT


def test_a_syntax_error_stops_the_node_being_made(ctx: Any) -> None:
    with pytest.raises(ScriptSyntaxError, match="line 1, column 6"):
        ScriptLeaf(ctx, "s", "", "x := ")


def test_a_script_in_a_scope_writes_there_and_at_sign_reaches_the_top(ctx: Any) -> None:
    scope = Scope(names="Pick#abcdef/", outer=Scope())
    node = ScriptLeaf(ctx, "s", "", "tries := 1; @picked := tries + 1", key=scope.key)
    assert node.tick() is SUCCESS
    assert ctx.blackboard.snapshot() == {"Pick#abcdef/tries": 1, "picked": 2.0}


def test_a_reactive_sequence_rechecks_a_script_condition(ctx: Any) -> None:
    ctx.blackboard.set("door_open", False)
    guard = ScriptLeaf(ctx, "g", "", "!door_open", condition=True)
    work = ScriptedLeaf(ctx, "work", RUNNING, RUNNING, RUNNING)
    seq = ReactiveSequence(ctx, "r", "r")
    seq.set_children([guard, work])
    assert seq.tick() is RUNNING
    ctx.blackboard.set("door_open", True)
    assert seq.tick() is FAILURE
    assert work.status is not RUNNING  # halted when the guard turned false


def test_a_plan_with_scripts_builds_and_runs(registry: CapabilityRegistry) -> None:
    tree_spec = logic(
        NodeKind.SEQUENCE,
        script("parts := 0"),
        logic(
            NodeKind.REPEAT,
            script("parts += 1", name="count a part"),
            count=3,
        ),
        condition("parts == 3"),
        op("debug.check_param", value="$parts", expected=3.0),
    )
    tree = build_tree(plan(tree_spec), registry)
    assert tree.tick_until_done() is SUCCESS
    assert tree.blackboard.get("parts") == 3


def test_a_bad_script_is_a_build_error_naming_the_node(registry: CapabilityRegistry) -> None:
    with pytest.raises(BuildError, match="code"):
        build_tree(plan(logic(NodeKind.SEQUENCE, script("x := (1"))), registry)


# --- validation ---------------------------------------------------------------------------


def problems(p: PlanSpec, registry: CapabilityRegistry) -> list[tuple[str, str]]:
    return [(pr.severity, pr.message) for pr in validate_plan(p, registry)]


def test_validation_reports_a_syntax_error_with_its_place(registry: CapabilityRegistry) -> None:
    found = problems(plan(logic(NodeKind.SEQUENCE, script("a := 1;\n  b := * 2"))), registry)
    assert any(
        severity == ERROR and "line 2, column 8" in message and "'code'" in message
        for severity, message in found
    ), found


def test_validation_needs_the_code(registry: CapabilityRegistry) -> None:
    found = problems(plan(logic(NodeKind.SEQUENCE, logic(NodeKind.SCRIPT))), registry)
    assert any(severity == ERROR and "'code'" in message for severity, message in found), found


def test_what_a_script_writes_can_be_read_after_it(registry: CapabilityRegistry) -> None:
    fine = plan(
        logic(NodeKind.SEQUENCE, script("GREETING := 'hi'"), op("debug.log", message="$GREETING"))
    )
    assert problems(fine, registry) == []
    early = plan(
        logic(NodeKind.SEQUENCE, op("debug.log", message="$GREETING"), script("GREETING := 'hi'"))
    )
    assert [s for s, _ in problems(early, registry)] == [WARNING]


def test_what_a_script_reads_must_be_set_somewhere(registry: CapabilityRegistry) -> None:
    found = problems(plan(logic(NodeKind.SEQUENCE, script("total := price * 2"))), registry)
    assert any(severity == ERROR and "Nothing sets price" in message for severity, message in found)
    ok = plan(logic(NodeKind.SEQUENCE, script("price := 3"), script("total := price * 2")))
    assert problems(ok, registry) == []


def test_a_branch_of_a_script_is_not_a_sure_write(registry: CapabilityRegistry) -> None:
    maybe = plan(
        logic(
            NodeKind.SEQUENCE,
            script("flag := false; flag ? (X := 1) : 0"),
            op("debug.log", message="$X"),
        )
    )
    assert [s for s, _ in problems(maybe, registry)] == [WARNING]


# --- files ------------------------------------------------------------------------------------


def test_scripts_come_back_from_the_plan_file_and_from_xml() -> None:
    p = plan(
        logic(
            NodeKind.SEQUENCE,
            script("A := 5;\nB := 'it''s'", name="set up"),
            condition("A > 1 && @B != ''"),
        )
    )
    again = loads_plan(dump_plan(p))
    assert again == p
    text = export_xml(again, {})
    assert "<Script name=\"set up\" code=\"A := 5;&#10;B := 'it''s'\"" in text
    assert "<ScriptCondition code=\"A &gt; 1 &amp;&amp; @B != ''\"" in text
    assert "TreeNodesModel" not in text or '<Action ID="Script"' not in text  # built-ins
    assert import_xml(text) == again


def test_btcpp_scripts_run_as_btcpp_runs_them(registry: CapabilityRegistry) -> None:
    xml = """<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="A:=5;&#10;B:=6" />
      <Script code=" level := 30; low := level &lt; 25 " />
      <ScriptCondition code="A + B == 11 &amp;&amp; !low" />
      <Script code="@total := A .. '/' .. B" />
    </Sequence>
  </BehaviorTree>
</root>"""
    p = import_xml(xml)
    kinds = [n.kind for _, n in p.walk()]
    assert kinds.count(NodeKind.SCRIPT) == 3 and NodeKind.SCRIPT_CONDITION in kinds
    assert problems(p, registry) == []
    tree = build_tree(p, registry)
    assert tree.tick_until_done() is SUCCESS
    assert tree.blackboard.snapshot() == {"A": 5, "B": 6, "level": 30, "low": False, "total": "5/6"}


def test_a_btcpp_script_that_fails_at_equals_fails_the_tree(registry: CapabilityRegistry) -> None:
    xml = """<root BTCPP_format="4"><BehaviorTree ID="Main"><Sequence>
      <Script code="ready = true" />
    </Sequence></BehaviorTree></root>"""
    tree = build_tree(import_xml(xml), registry)
    assert tree.tick_until_done() is FAILURE
