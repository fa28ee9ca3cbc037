"""BehaviorTree.CPP 4.10's built-in nodes as plan nodes: read from v4 XML, validated (the
numbers of children BehaviorTree.CPP takes), built, run, written back, and saved in plans.
"""

from __future__ import annotations

from typing import Any

import pytest
from bt_fakes import logic, plan

from capabilities.base import CapabilityRegistry
from engine.btcpp import export_xml, import_xml
from engine.build import build_tree
from engine.files import dump_plan, loads_plan
from engine.kinds import KIND_DOC, KIND_PORTS
from engine.spec import KIND_CATEGORY, NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, RUNNING, SUCCESS
from engine.validation import ERROR, validate_plan

EVERY_BUILTIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SetBlackboard value="2" output_key="mode"/>
      <Switch3 variable="{mode}" case_1="1" case_2="2" case_3="3">
        <AlwaysFailure/>
        <Script code="picked := 'two'"/>
        <AlwaysFailure/>
        <AlwaysFailure/>
      </Switch3>
      <IfThenElse>
        <ScriptCondition code="picked == 'two'"/>
        <AlwaysSuccess/>
        <AlwaysFailure/>
      </IfThenElse>
      <WhileDoElse>
        <ScriptCondition code="false"/>
        <AlwaysFailure/>
        <AlwaysSuccess/>
      </WhileDoElse>
      <SequenceWithMemory>
        <AsyncSequence><AlwaysSuccess/><AlwaysSuccess/></AsyncSequence>
        <AsyncFallback><AlwaysFailure/><AlwaysSuccess/></AsyncFallback>
      </SequenceWithMemory>
      <ParallelAll max_failures="2">
        <AlwaysFailure/>
        <Delay delay_msec="0"><AlwaysSuccess/></Delay>
      </ParallelAll>
      <Parallel success_count="-2" failure_count="3">
        <AlwaysSuccess/><AlwaysSuccess/><AlwaysFailure/>
      </Parallel>
      <TryCatch catch_on_halt="true">
        <AlwaysSuccess/>
        <AlwaysFailure/>
      </TryCatch>
      <Inverter>
        <KeepRunningUntilFailure><AlwaysFailure/></KeepRunningUntilFailure>
      </Inverter>
      <RunOnce then_skip="false"><AlwaysSuccess/></RunOnce>
      <Precondition if="picked == 'two'" else="FAILURE"><AlwaysSuccess/></Precondition>
      <SetBlackboard value="{picked}" output_key="copy"/>
      <UnsetBlackboard key="copy"/>
      <WasEntryUpdated entry="mode"/>
      <SkipUnlessUpdated entry="{picked}"><AlwaysSuccess/></SkipUnlessUpdated>
      <WaitValueUpdate entry="mode"><AlwaysSuccess/></WaitValueUpdate>
    </Sequence>
  </BehaviorTree>
</root>
"""

NEW_KINDS = [
    NodeKind.SEQUENCE_WITH_MEMORY,
    NodeKind.ASYNC_SEQUENCE,
    NodeKind.ASYNC_FALLBACK,
    NodeKind.PARALLEL_ALL,
    NodeKind.IF_THEN_ELSE,
    NodeKind.WHILE_DO_ELSE,
    NodeKind.SWITCH,
    NodeKind.TRY_CATCH,
    NodeKind.KEEP_RUNNING_UNTIL_FAILURE,
    NodeKind.DELAY,
    NodeKind.RUN_ONCE,
    NodeKind.PRECONDITION,
    NodeKind.ALWAYS_SUCCESS,
    NodeKind.ALWAYS_FAILURE,
    NodeKind.SET_BLACKBOARD,
    NodeKind.UNSET_BLACKBOARD,
    NodeKind.SKIP_UNLESS_UPDATED,
    NodeKind.WAIT_VALUE_UPDATE,
    NodeKind.WAS_ENTRY_UPDATED,
]


def kinds_of(spec: PlanSpec) -> set[NodeKind]:
    return {node.kind for _, node in spec.walk()}


def test_every_new_kind_has_a_doc_and_a_category() -> None:
    for kind in NEW_KINDS:
        assert KIND_DOC[kind] and kind in KIND_CATEGORY


def test_a_file_of_builtin_nodes_imports_validates_and_runs_to_success(
    registry: CapabilityRegistry,
) -> None:
    spec = import_xml(EVERY_BUILTIN, "builtins.xml")
    assert set(NEW_KINDS) <= kinds_of(spec)
    assert [p for p in validate_plan(spec, registry) if p.severity == ERROR] == []
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(max_ticks=50) is SUCCESS
    assert tree.blackboard.snapshot() == {"mode": "2", "picked": "two"}


def test_builtin_nodes_go_to_xml_and_back_unchanged() -> None:
    spec = import_xml(EVERY_BUILTIN, "builtins.xml")
    written = export_xml(spec, {})
    assert "<Switch3 " in written and 'ID="Switch' not in written  # a built-in: no model
    again = import_xml(written, "again.xml")
    assert dump_plan(again) == dump_plan(spec)


def test_builtin_nodes_are_saved_and_read_in_plan_files() -> None:
    spec = import_xml(EVERY_BUILTIN, "builtins.xml")
    text = dump_plan(spec)
    assert dump_plan(loads_plan(text)) == text


def test_settings_keep_their_btcpp_defaults() -> None:
    defaults = {
        (kind, port.name): port.default for kind in NEW_KINDS for port in KIND_PORTS.get(kind, ())
    }
    assert defaults[NodeKind.PARALLEL_ALL, "max_failures"] == 1
    assert defaults[NodeKind.TRY_CATCH, "catch_on_halt"] == "false"
    assert defaults[NodeKind.RUN_ONCE, "then_skip"] == "true"
    assert defaults[NodeKind.PRECONDITION, "else"] == "FAILURE"
    assert defaults[NodeKind.PRECONDITION, "if"] is None  # required, as in BehaviorTree.CPP
    assert defaults[NodeKind.DELAY, "seconds"] is None


def errors(spec: NodeSpec, registry: CapabilityRegistry) -> list[str]:
    return [p.message for p in validate_plan(plan(spec), registry) if p.severity == ERROR]


def ok() -> NodeSpec:
    return logic(NodeKind.ALWAYS_SUCCESS)


@pytest.mark.parametrize(
    ("kind", "children", "fine"),
    [
        (NodeKind.IF_THEN_ELSE, 1, False),
        (NodeKind.IF_THEN_ELSE, 2, True),
        (NodeKind.IF_THEN_ELSE, 3, True),
        (NodeKind.IF_THEN_ELSE, 4, False),
        (NodeKind.WHILE_DO_ELSE, 4, False),
        (NodeKind.TRY_CATCH, 1, False),
        (NodeKind.TRY_CATCH, 5, True),
        (NodeKind.SWITCH, 2, False),
        (NodeKind.SWITCH, 7, True),
        (NodeKind.SWITCH, 8, False),
    ],
)
def test_validation_counts_children_as_btcpp_does(
    registry: CapabilityRegistry, kind: NodeKind, children: int, fine: bool
) -> None:
    config: dict[str, Any] = {"variable": "{x}"} if kind is NodeKind.SWITCH else {}
    node = logic(kind, *[ok() for _ in range(children)], **config)
    found = [m for m in errors(node, registry) if "nodes below it" in m]
    assert (found == []) is fine, found


def test_validation_refuses_a_case_without_a_node_and_a_bad_word(
    registry: CapabilityRegistry,
) -> None:
    node = logic(NodeKind.SWITCH, ok(), ok(), ok(), variable="{x}", case_3="7")
    assert any("'case_3' has no node to run" in m for m in errors(node, registry))
    node = logic(NodeKind.RUN_ONCE, ok(), then_skip="maybe")
    assert any("then_skip" in m for m in errors(node, registry))
    node = logic(NodeKind.PRECONDITION, ok(), **{"if": "x := "})
    assert any("a script" in m for m in errors(node, registry))
    node = logic(NodeKind.PARALLEL_ALL, ok(), max_failures=3)
    assert any("only 1 children" in m for m in errors(node, registry))
    node = logic(NodeKind.PARALLEL, ok(), ok(), success=0)
    assert any("other than 0" in m for m in errors(node, registry))


def test_a_set_blackboard_counts_as_the_writer_of_its_key(registry: CapabilityRegistry) -> None:
    reads = logic(NodeKind.SCRIPT_CONDITION, code="ready == 'yes'")
    tree = logic(
        NodeKind.SEQUENCE, logic(NodeKind.SET_BLACKBOARD, value="yes", output_key="ready"), reads
    )
    assert errors(tree, registry) == []


@pytest.mark.parametrize(("otherwise", "expected"), [(None, FAILURE), ("SUCCESS", SUCCESS)])
def test_precondition_else_runs_from_a_plan(
    registry: CapabilityRegistry, otherwise: str | None, expected: Any
) -> None:
    config = {"if": "false", "else": otherwise}
    spec = plan(logic(NodeKind.PRECONDITION, logic(NodeKind.ALWAYS_FAILURE), **config))
    assert build_tree(spec, registry).tick_until_done(max_ticks=5) is expected


def run_again(tree: Any, times: int) -> list[Any]:
    """The tree ticked ``times`` times, reset after each finish (BehaviorTree.CPP's tickOnce
    on a tree that finished).
    """
    results = []
    for _ in range(times):
        if tree.status in (SUCCESS, FAILURE):
            tree.reset()
        results.append(tree.tick())
    return results


def test_sequence_with_memory_resumes_at_the_failed_condition_issue_636(
    registry: CapabilityRegistry,
) -> None:
    spec = plan(
        logic(
            NodeKind.SEQUENCE_WITH_MEMORY,
            logic(NodeKind.SCRIPT, code="var := 0"),
            logic(NodeKind.ALWAYS_SUCCESS, name="A"),
            logic(NodeKind.SCRIPT_CONDITION, code="var += 1; var >= 5"),
            logic(NodeKind.ALWAYS_SUCCESS, name="B"),
        )
    )
    tree = build_tree(spec, registry)
    # a tick given back after each child that succeeded at once (BehaviorTree.CPP's tickOnce
    # takes those ticks in one: its test counts 5)
    assert run_again(tree, 8) == [RUNNING, RUNNING, *[FAILURE] * 4, RUNNING, SUCCESS]
    assert tree.blackboard.get("var") == 5  # the Script ran once: the sequence kept its place


def test_run_once_runs_its_child_in_the_first_run_only(registry: CapabilityRegistry) -> None:
    spec = plan(
        logic(
            NodeKind.SEQUENCE,
            logic(NodeKind.RUN_ONCE, logic(NodeKind.SCRIPT, code="a += 1")),
            logic(NodeKind.SCRIPT, code="b += 1"),
        )
    )
    tree = build_tree(spec, registry)
    tree.blackboard.set("a", 0)
    tree.blackboard.set("b", 0)
    assert run_again(tree, 5) == [SUCCESS] * 5
    assert (tree.blackboard.get("a"), tree.blackboard.get("b")) == (1, 5)
