"""Pre- and post-conditions in plans: the file (format 4, older files unchanged), the build
(scripts run in the node's scope; an instance's in the scope it is in) and validation.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from bt_fakes import logic, op, plan

from capabilities.base import CapabilityRegistry
from engine.build import BuildError, build_tree
from engine.conditions import Condition
from engine.files import dump_plan, loads_plan
from engine.library import dump_subtree, load_subtree
from engine.plan_format import PlanFileError
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec, SubtreePort, SubtreeSpec
from engine.status import FAILURE, SKIPPED, SUCCESS
from engine.types import ParamType
from engine.validation import ERROR, WARNING, validate_plan


def script(code: str, name: str = "") -> NodeSpec:
    return logic(NodeKind.SCRIPT, name=name, code=code)


def conditioned(node: NodeSpec, **texts: str) -> NodeSpec:
    node.conditions = {Condition(k.rstrip("_")): v for k, v in texts.items()}
    return node


def problems(p: PlanSpec, registry: CapabilityRegistry) -> list[tuple[str, str | None, str]]:
    return [(pr.severity, pr.field, pr.message) for pr in validate_plan(p, registry)]


# ---------------------------------------------------------------- the file


def test_conditions_round_trip_as_format_4_in_a_fixed_order() -> None:
    p = plan(
        logic(
            NodeKind.SEQUENCE,
            script("A := 1"),
            conditioned(op("debug.succeed"), post="n := 1", skip_if="A != 1", on_halted="h := 1"),
        )
    )
    text = dump_plan(p)
    doc = json.loads(text)
    assert doc["format_version"] == 4
    node = doc["tree"]["children"][1]
    assert list(node["conditions"]) == ["skip_if", "post", "on_halted"]
    again = loads_plan(text)
    assert again == p and dump_plan(again) == text


def test_a_plan_without_conditions_keeps_its_older_version() -> None:
    p = plan(logic(NodeKind.SEQUENCE, conditioned(op("debug.succeed"), skip_if="  ")))
    doc = json.loads(dump_plan(p))
    assert doc["format_version"] == 2 and "conditions" not in doc["tree"]["children"][0]


def test_shipped_examples_read_unchanged_and_write_the_same_bytes() -> None:
    from resources import resource_path

    for path in sorted(Path(resource_path("examples")).rglob("*.costar.json")):
        text = path.read_text(encoding="utf-8")
        assert dump_plan(loads_plan(text)) == text, path


def test_an_unknown_condition_is_refused_with_its_path() -> None:
    p = plan(logic(NodeKind.SEQUENCE, op("debug.succeed")))
    doc = json.loads(dump_plan(p))
    doc["tree"]["children"][0]["conditions"] = {"skipIf": "true"}
    with pytest.raises(PlanFileError) as info:
        loads_plan(json.dumps(doc))
    assert "conditions.skipIf" in str(info.value) and "skip_if" in str(info.value)


def test_a_library_subtree_with_conditions_is_version_2_and_reads_back(tmp_path: Path) -> None:
    inner = logic(NodeKind.SEQUENCE, conditioned(op("debug.succeed"), skip_if="true"))
    sub = SubtreeSpec(id="t.s", name="S", tree=inner, date="2026-11-24T19:40:00Z")
    file = tmp_path / "S.subtree.json"
    file.write_text(dump_subtree(sub), encoding="utf-8")
    assert json.loads(file.read_text())["format_version"] == 2
    assert load_subtree(file) == sub
    inner.children[0].conditions = {}
    assert json.loads(dump_subtree(sub))["format_version"] == 1


# ---------------------------------------------------------------- build and run


def test_conditions_run_in_a_built_plan(registry: CapabilityRegistry) -> None:
    p = plan(
        logic(
            NodeKind.SEQUENCE,
            script("A := 1; done := 0"),
            conditioned(op("debug.fail", "never"), skip_if="A == 1"),
            conditioned(op("debug.succeed", "ok"), on_success="done = 1"),
        )
    )
    tree = build_tree(p, registry)
    assert tree.tick_until_done() is SUCCESS
    assert tree.blackboard.get("done") == 1


def test_a_condition_that_does_not_parse_is_a_build_error(registry: CapabilityRegistry) -> None:
    p = plan(logic(NodeKind.SEQUENCE, conditioned(op("debug.succeed"), while_="a ==")))
    with pytest.raises(BuildError, match="while condition is not a script"):
        build_tree(p, registry)


def _sub(tree: NodeSpec, inputs: list[SubtreePort] | None = None) -> SubtreeSpec:
    return SubtreeSpec(id="t.sub", name="Sub", tree=tree, inputs=inputs or [])


def test_an_instance_skipped_by_its_condition_never_runs_its_inside(
    registry: CapabilityRegistry,
) -> None:
    inside = _sub(script("ran := true"))
    instance = conditioned(
        NodeSpec(NodeKind.SUBTREE, name="sub", subtree=inside.ref), skip_if="data"
    )
    p = plan(
        logic(NodeKind.SEQUENCE, script("data := true"), instance, script("after := 1")),
        subtrees=[inside],
    )
    tree = build_tree(p, registry)
    assert tree.tick_until_done() is SUCCESS
    assert "ran" not in tree.blackboard.snapshot() and tree.blackboard.get("after") == 1
    assert tree.nodes[instance.id].status is SKIPPED


def test_conditions_inside_a_subtree_read_its_own_ports(registry: CapabilityRegistry) -> None:
    """An inner instance's skip condition reads the outer subtree's port, bound three ways."""
    leaf = _sub(script("@count := @count + 1"))
    middle = _sub(
        conditioned(NodeSpec(NodeKind.SUBTREE, name="inner", subtree=leaf.ref), skip_if="!param"),
        [SubtreePort("param", ParamType.BOOL)],
    )
    middle.id, middle.name = "t.middle", "Middle"

    def use(binding: Binding) -> NodeSpec:
        return NodeSpec(NodeKind.SUBTREE, subtree=middle.ref, params={"param": binding})

    p = plan(
        logic(
            NodeKind.SEQUENCE,
            script("@count := 0; value := true; off := false"),
            use(Binding.reference("value")),
            use(Binding.reference("off")),
            use(Binding.fixed(True, ParamType.BOOL)),
        ),
        subtrees=[leaf, middle],
    )
    tree = build_tree(p, registry)
    assert tree.tick_until_done() is SUCCESS
    assert tree.blackboard.get("count") == 2


# ---------------------------------------------------------------- validation


def test_a_condition_with_a_syntax_error_is_reported_with_line_and_column(
    registry: CapabilityRegistry,
) -> None:
    p = plan(
        logic(
            NodeKind.SEQUENCE,
            conditioned(op("debug.succeed", "go"), on_failure="x := 1;\n  y := * 2"),
        )
    )
    found = problems(p, registry)
    assert [(s, f) for s, f, _ in found] == [(ERROR, "on_failure")]
    assert "on failure condition of 'go'" in found[0][2] and "line 2, column 8" in found[0][2]


def test_what_a_condition_reads_must_be_set_and_what_it_writes_is_written(
    registry: CapabilityRegistry,
) -> None:
    unset = plan(logic(NodeKind.SEQUENCE, conditioned(op("debug.succeed"), skip_if="ready")))
    assert any(
        s == ERROR and f == "skip_if" and "Nothing sets ready" in m
        for s, f, m in problems(unset, registry)
    )
    written = plan(
        logic(
            NodeKind.SEQUENCE,
            conditioned(op("debug.succeed"), on_success="GREETING := 'hi'"),
            op("debug.log", message="$GREETING"),
        )
    )
    assert problems(written, registry) == []


def test_a_node_that_may_be_passed_over_guarantees_nothing(registry: CapabilityRegistry) -> None:
    for condition in ("skip_if", "success_if", "while_"):
        p = plan(
            logic(
                NodeKind.SEQUENCE,
                script("flag := true"),
                conditioned(script("GREETING := 'hi'"), **{condition: "flag"}),
                op("debug.log", message="$GREETING"),
            )
        )
        assert [s for s, _, _ in problems(p, registry)] == [WARNING], condition


def test_a_post_condition_may_read_what_its_node_wrote(registry: CapabilityRegistry) -> None:
    p = plan(
        logic(NodeKind.SEQUENCE, conditioned(script("n := 1"), on_success="m := n + 1", post="n"))
    )
    assert problems(p, registry) == []
    early = plan(logic(NodeKind.SEQUENCE, conditioned(script("n := 1"), on_failure="n")))
    assert [s for s, _, _ in problems(early, registry)] == [WARNING]


# ---------------------------------------------------------------- BehaviorTree.CPP XML


def test_conditions_are_btcpp_attributes_both_ways(registry: CapabilityRegistry) -> None:
    from engine.btcpp import export_xml, import_xml

    p = plan(
        logic(
            NodeKind.SEQUENCE,
            script("A := 1"),
            conditioned(op("debug.succeed", "go"), skip_if="A != 1", on_success="B := 'a&b'"),
            conditioned(
                logic(NodeKind.FORCE_SUCCESS, conditioned(script("C := 1"), while_="A == 1")),
                post="D := 2;\nE := 3",
                on_halted="F := 1",
            ),
        )
    )
    manifests = {m.id: m for m in registry.manifests()}
    text = export_xml(p, manifests)
    assert '_skipIf="A != 1" _onSuccess="B := \'a&amp;b\'"' in text
    assert '_post="D := 2;&#10;E := 3" _onHalted="F := 1"' in text and '_while="A == 1"' in text
    assert import_xml(text, manifests=manifests) == p


def test_btcpp_conditions_run_as_btcpp_runs_them(registry: CapabilityRegistry) -> None:
    from engine.btcpp import import_xml

    xml = """<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="x := 0; y := 0; skip := true" />
      <RetryUntilSuccessful num_attempts="3">
        <ScriptCondition code="false" _onFailure="x += 1" _post="y += 1" />
      </RetryUntilSuccessful>
    </Sequence>
  </BehaviorTree>
</root>"""
    p = import_xml(xml)
    tree = build_tree(p, registry)
    assert tree.tick_until_done() is FAILURE
    assert (tree.blackboard.get("x"), tree.blackboard.get("y")) == (3, 3)
    skipping = import_xml(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence>'
        '<Script code="skip := true" _onSuccess="after := 1"/>'
        '<ScriptCondition code="false" _skipIf="skip"/>'
        "</Sequence></BehaviorTree></root>"
    )
    tree = build_tree(skipping, registry)
    assert tree.tick_until_done() is SUCCESS and tree.blackboard.get("after") == 1


def test_the_schema_takes_conditions_and_refuses_unknown_ones() -> None:
    import jsonschema

    from resources import resource_path

    schema = json.loads(Path(resource_path("schemas/plan.schema.json")).read_text("utf-8"))
    validator = jsonschema.Draft202012Validator(schema)
    p = plan(logic(NodeKind.SEQUENCE, conditioned(op("debug.succeed"), while_="go", post="n")))
    doc = json.loads(dump_plan(p))
    assert list(validator.iter_errors(doc)) == []
    doc["tree"]["children"][0]["conditions"]["skipIf"] = "x"
    assert list(validator.iter_errors(doc))
