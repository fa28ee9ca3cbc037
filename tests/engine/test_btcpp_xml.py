"""BehaviorTree.CPP v4 XML both ways (engine.btcpp), without a capability registry."""

from __future__ import annotations

import dataclasses
import math
import random
import re
from pathlib import Path

import pytest

from engine.btcpp import XmlExportError, XmlFileError, export_xml, import_xml, load_xml
from engine.btcpp.names import decode_id, decode_port, encode_id, encode_port, is_model_name
from engine.btcpp.values import parse_value, value_text
from engine.files import dump_plan, load_plan, loads_plan
from engine.spec import (
    Binding,
    NodeKind,
    NodeLayout,
    NodeSpec,
    ParameterDecl,
    PlanSpec,
    RunPolicy,
    SubtreePort,
    SubtreeSpec,
)
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Region, Waypoint, WaypointFrame

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "resources").rglob("*.costar.json"))


def _round_trip(plan: PlanSpec) -> PlanSpec:
    return import_xml(export_xml(plan, {}), "plan.xml")


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_shipped_example_comes_back_equal(path: Path) -> None:
    plan = load_plan(path)
    again = _round_trip(plan)
    assert again == plan  # the spec: tree, ids, bindings and their types, layout, waypoints
    assert dump_plan(again) == dump_plan(plan)


def test_the_examples_are_found() -> None:
    assert len(EXAMPLES) >= 20


def _transfer() -> SubtreeSpec:
    inner = NodeSpec(
        NodeKind.SEQUENCE,
        name="transfer",
        children=[
            NodeSpec(
                NodeKind.OPERATION,
                op="markers.object_pose",
                params={"object": Binding.reference("OBJECT"), "pose": Binding.reference("PLACED")},
            ),
            NodeSpec(
                NodeKind.OPERATION, op="debug.log", params={"message": Binding.reference("BIN")}
            ),
        ],
    )
    return SubtreeSpec(
        id="kitting.transfer",
        name="Transfer",
        tree=inner,
        version=2,
        date="2026-11-24T19:40:00Z",
        description="moves one plate into the bin",
        inputs=[SubtreePort("OBJECT", ParamType.OBJECT, "which plate", ObjectModel("plate_8"))],
        outputs=[SubtreePort("PLACED", ParamType.POSE, "where it went")],
        shared_names=["BIN"],
        layout={inner.id: NodeLayout(10.5, -3.25, collapsed=True)},
    )


def _kitting() -> PlanSpec:
    sub = _transfer()
    four = NodeSpec(
        NodeKind.SUBTREE,
        name="Transfer 4-hole",
        subtree=sub.ref,
        params={
            "OBJECT": Binding.fixed(ObjectModel("plate_4"), ParamType.OBJECT),
            "PLACED": Binding.reference("P4_PLACED"),
        },
    )
    eight = NodeSpec(NodeKind.SUBTREE, name="Transfer 8-hole", subtree=sub.ref)
    root = NodeSpec(NodeKind.SEQUENCE, name="kitting", children=[four, eight])
    plan = PlanSpec(tree=root, name="Kitting", subtrees=[sub])
    plan.layout = {four.id: NodeLayout(0.0, 100.0), eight.id: NodeLayout(200.0, 100.0)}
    return loads_plan(dump_plan(plan))  # as a file gives it


def test_subtrees_are_behavior_trees_and_instances_remap_their_ports() -> None:
    plan = _kitting()
    text = export_xml(plan, {})
    assert '<BehaviorTree ID="Transfer" _uid="kitting.transfer"' in text
    assert 'main_tree_to_execute="Kitting"' in text
    # inputs and outputs remapped; the shared name to itself; an unused output to a sink
    assert 'OBJECT="plate_4" PLACED="{P4_PLACED}"' in text
    assert 'name="Transfer 8-hole" PLACED="{_}" BIN="{BIN}"' in text
    assert '<input_port name="OBJECT" type="costar::ObjectModel" default="plate_8"' in text
    again = import_xml(text, "kitting.xml")
    assert again == plan
    assert dump_plan(again) == dump_plan(plan)


def test_sibling_instances_of_one_name_get_names_btcpp_accepts_and_come_back() -> None:
    """BehaviorTree.CPP 4.10 refuses two SubTree siblings with one name (their paths)."""
    plan = _kitting()
    for instance in plan.tree.children:
        instance.name = "Transfer"
    text = export_xml(plan, {})
    names = re.findall(r'<SubTree ID="Transfer" name="([^"]*)"', text)
    assert names == ["Transfer", "Transfer (2)"]
    again = import_xml(text, "kitting.xml")
    assert [c.name for c in again.tree.children] == ["Transfer", "Transfer"]
    assert dump_plan(again) == dump_plan(plan)


def test_an_instance_without_its_definition_is_not_exported() -> None:
    plan = _kitting()
    plan.subtrees = []
    with pytest.raises(XmlExportError, match="definition of the subtree"):
        export_xml(plan, {})


def test_an_empty_plan_says_so() -> None:
    with pytest.raises(XmlExportError, match="a tree to export"):
        export_xml(PlanSpec(name="nothing"), {})


def test_plan_data_parameters_waypoints_objects_and_off_tree_layout_come_back() -> None:
    leaf = NodeSpec(
        NodeKind.OPERATION,
        op="debug.set_param",
        params={
            "name": Binding.fixed("X", ParamType.TEXT),  # a port called "name": p_name
            "value": Binding.fixed(Region((0.1, 0.2, 0.3), 0.05), ParamType.REGION),
        },
    )
    plan = PlanSpec(
        tree=leaf,
        name="data: all of it / <here>",
        description='quotes " and\nnewlines\r\nand tabs\t',
        run_policy=RunPolicy.UNTIL_SUCCESS,
        give_up_after=0,
        reset_cell=True,
        parameters=[
            ParameterDecl("HOME", ParamType.JOINTS, JointConfig((0.1, -1.2, 3.0)), "home"),
            ParameterDecl("EMPTY", ParamType.TEXT, ""),
            ParameterDecl("UNSET", ParamType.POSE),
        ],
        waypoints=[Waypoint("w", WaypointFrame.MARKER, Pose((1, 2, 3)), reference="7")],
        objects=["cup", "plate_4"],
        layout={leaf.id: NodeLayout(1.0, 2.0), "gone": NodeLayout(5.0, 6.0)},
    )
    plan = loads_plan(dump_plan(plan))
    text = export_xml(plan, {})
    assert 'p_name="X"' in text
    assert _round_trip(plan) == plan


def test_settings_that_builtins_cannot_hold_exactly_keep_their_exact_value() -> None:
    wait = NodeSpec(NodeKind.WAIT, params={"seconds": Binding.fixed(0.0005, ParamType.DURATION)})
    timeout = NodeSpec(
        NodeKind.TIMEOUT,
        params={"seconds": Binding.fixed(2.5, ParamType.DURATION)},
        children=[wait],
    )
    parallel = NodeSpec(
        NodeKind.PARALLEL,
        params={
            "success": Binding.fixed(1.0, ParamType.NUMBER),  # 1, not the word "any"
            "failure": Binding.fixed("any", ParamType.TEXT),
        },
        children=[timeout],
    )
    plan = loads_plan(dump_plan(PlanSpec(tree=parallel, name="settings")))
    text = export_xml(plan, {})
    assert 'failure_count="1" success_count="1" _success="1.0"' in text
    assert '<Timeout msec="2500"' in text
    assert 'msec="0" _seconds="0.0005"' in text
    assert _round_trip(plan) == plan


def test_unknown_node_types_are_all_reported_with_their_lines() -> None:
    text = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <OpenDoor speed="1"/>
      <Levitate height="{x}">
        <FlyAway/>
        <IsAirborne entry="{x}"/>
        <Hover/>
      </Levitate>
      <Sleep msec="soon"/>
      <Inverter _skipIf="x == 1"><Action ID="Teleport"/></Inverter>
    </Sequence>
  </BehaviorTree>
</root>
"""
    with pytest.raises(XmlFileError) as caught:
        import_xml(text, "door.xml")
    problems = caught.value.problems
    unknown = [(p.line, p.got) for p in problems if p.got.startswith("unknown node type")]
    assert unknown == [
        (4, "unknown node type 'OpenDoor'"),
        (5, "unknown node type 'Levitate'"),
        (6, "unknown node type 'FlyAway'"),
        (7, "unknown node type 'IsAirborne'"),
        (8, "unknown node type 'Hover'"),
        (11, "unknown node type 'Teleport'"),
    ]
    message = str(caught.value)
    assert "door.xml: line 10: expected msec a number, got 'soon'" in message


def test_known_operations_need_their_models_or_the_registry() -> None:
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="M"><debug__log text="hi"/></BehaviorTree></root>'
    )
    with pytest.raises(XmlFileError, match=r"line 1: .*unknown node type 'debug__log'"):
        import_xml(text, "m.xml")
    declared = text.replace(
        "</root>",
        '<TreeNodesModel><Action ID="debug__log"><input_port name="text"/></Action>'
        "</TreeNodesModel></root>",
    )
    plan = import_xml(declared, "m.xml")
    assert plan.tree is not None and plan.tree.op == "debug.log"
    assert plan.tree.params["text"] == Binding.fixed("hi", ParamType.TEXT)


@pytest.mark.parametrize(
    ("text", "line", "expected"),
    [
        ('<root BTCPP_format="4">\n<BehaviorTree ID="M">\n<Sequence>\n</root>', 4, "well-formed"),
        ('<!DOCTYPE r [<!ENTITY a "aaaa">]>\n<root/>', 1, "well-formed"),
        ('<root BTCPP_format="4">\n<BehaviorTree ID="M"/></root>', 2, "one root node"),
        ('<trees BTCPP_format="4"/>', 1, "<root"),
        ('<root BTCPP_format="4" main_tree_to_execute="X"/>', 1, "main tree"),
    ],
)
def test_malformed_files_name_the_line(text: str, line: int, expected: str) -> None:
    with pytest.raises(XmlFileError) as caught:
        import_xml(text, "bad.xml")
    assert caught.value.problems[0].line == line
    assert expected in str(caught.value)
    assert str(caught.value).startswith("bad.xml: line")


def test_a_file_that_is_not_utf8_or_missing_names_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "latin.xml"
    bad.write_bytes(b"<root>\xe9</root>")
    with pytest.raises(XmlFileError, match=r"latin\.xml: .*UTF-8"):
        load_xml(bad)
    with pytest.raises(XmlFileError, match=r"nothere\.xml"):
        load_xml(tmp_path / "nothere.xml")


@pytest.mark.parametrize(
    "name",
    ["motion.move_to", "a__b", "my op.x", "_x", "x.", ".x", "root", "Sequence", "é.b", "a_.b", "9"],
)
def test_ids_map_reversibly_to_names_btcpp_accepts(name: str) -> None:
    model = encode_id(name, avoid={"Sequence"})
    assert decode_id(model) == name
    assert is_model_name(model) and (model[0].isalpha() or model[0] == "_")
    port = encode_port(name)
    assert decode_port(port) == name and port[0].isalpha() and is_model_name(port)


def test_the_usual_operation_id_reads_naturally() -> None:
    assert encode_id("motion.move_to") == "motion__move_to"
    assert encode_port("target") == "target"


def test_values_come_back_exactly_including_floats() -> None:
    rng = random.Random(7)
    for _ in range(200):
        angle = rng.uniform(-math.pi, math.pi)
        position = (rng.uniform(-2, 2), rng.uniform(-2, 2), rng.random() * 1e-7)
        pose = Pose(position, (0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2)))
        number = rng.uniform(-1e9, 1e9) * rng.choice([1e-12, 1.0, 1e12])
        for ptype, value in [
            (ParamType.POSE, pose),
            (ParamType.NUMBER, number),
            (ParamType.JOINTS, JointConfig(position)),
            (ParamType.WAYPOINT, Waypoint("w", pose=pose)),
            (ParamType.ANY, {"a": [number, "t"]}),
        ]:
            assert parse_value(ptype, value_text(ptype, value)) == value
    assert value_text(ParamType.POSE, Pose()) == "0.0;0.0;0.0;0.0;0.0;0.0;1.0"
    assert parse_value(ParamType.BOOL, "false") is False


@pytest.mark.parametrize(
    ("ptype", "text", "expected"),
    [
        (ParamType.POSE, "1;2;3", "x;y;z;qx;qy;qz;qw"),
        (ParamType.NUMBER, "nan", "finite"),
        (ParamType.BOOL, "yes", "true or false"),
        (ParamType.WAYPOINT, '{"name": "w"}', "json:"),
        (ParamType.DURATION, "-1", "not negative"),
    ],
)
def test_a_bad_value_text_says_what_was_expected(
    ptype: ParamType, text: str, expected: str
) -> None:
    with pytest.raises(ValueError, match=expected):
        parse_value(ptype, text)


def test_damaged_files_give_problems_never_other_exceptions() -> None:
    """Every attribute value of an exported plan replaced in turn with junk: the import
    succeeds or raises XmlFileError (a broken file never crashes the app).
    """
    text = export_xml(_kitting(), {})
    junk = ["", "{", "nan", "-1", "json:{", "1;2", "{=}", "x" * 3, "_5g_", "inf", "true"]
    rng = random.Random(3)
    values = list(dict.fromkeys(re.findall(r'="([^"]*)"', text)))
    outcomes = set()
    for value in values:
        damaged = text.replace(f'="{value}"', f'="{rng.choice(junk)}"')
        try:
            import_xml(damaged, "damaged.xml")
            outcomes.add("read")
        except XmlFileError as exc:
            assert exc.problems and all(p.line >= 1 for p in exc.problems)
            outcomes.add("problems")
    assert outcomes == {"read", "problems"}


def test_every_field_of_the_spec_is_carried() -> None:
    """A new field of the plan spec must be taught to engine.btcpp (writer and read_parts),
    or the XML round trip silently drops it: this test names the fields it knows.
    """
    carried = {
        PlanSpec: {"tree", "name", "description", "run_policy", "give_up_after", "reset_cell"}
        | {"scene"}
        | {"parameters", "waypoints", "objects", "layout", "id", "subtrees"},
        NodeSpec: {"kind", "name", "id", "op", "params", "children", "subtree", "conditions"},
        SubtreeSpec: {"id", "name", "tree", "version", "date", "description", "inputs"}
        | {"outputs", "shared_names", "layout"},
        SubtreePort: {"name", "type", "doc", "default"},
        NodeLayout: {"x", "y", "collapsed"},
        ParameterDecl: {"name", "type", "value", "doc"},
    }
    for spec, known in carried.items():
        assert {f.name for f in dataclasses.fields(spec)} == known, spec.__name__


@pytest.mark.parametrize("text", ["bell\x07", "lone \ud800"])
def test_text_xml_cannot_hold_is_refused_by_node(text: str) -> None:
    leaf = NodeSpec(NodeKind.OPERATION, op="debug.log", name="say it")
    leaf.params["message"] = Binding.fixed(text, ParamType.TEXT)
    with pytest.raises(XmlExportError, match=r"say it \[message\]: expected text without"):
        export_xml(PlanSpec(tree=leaf, name="p"), {})
    leaf.params.clear()
    leaf.name = text
    with pytest.raises(XmlExportError, match="control characters"):
        export_xml(PlanSpec(tree=leaf, name="p"), {})


def _nested() -> PlanSpec:
    """A subtree holding instances of another, two versions of one subtree, and a plan named
    like one of its subtrees.
    """
    msg = [SubtreePort("MSG", ParamType.TEXT)]
    log = NodeSpec(NodeKind.OPERATION, op="debug.log", params={"message": Binding.reference("MSG")})
    inner = SubtreeSpec(id="a.inner", name="Inner", tree=log, inputs=msg)
    inner_v2 = SubtreeSpec(
        id="a.inner", name="Inner", version=2, tree=NodeSpec(NodeKind.OPERATION, op="debug.succeed")
    )
    uses = [
        NodeSpec(NodeKind.SUBTREE, subtree=inner.ref, params={"MSG": Binding.fixed("hi", _TEXT)}),
        NodeSpec(NodeKind.SUBTREE, subtree=inner.ref, params={"MSG": Binding.reference("OUT")}),
    ]
    outer = SubtreeSpec(
        id="a.outer",
        name="Outer",
        tree=NodeSpec(NodeKind.SEQUENCE, children=uses),
        inputs=[SubtreePort("OUT", ParamType.TEXT, default="x")],
    )
    root = NodeSpec(
        NodeKind.SEQUENCE,
        children=[
            NodeSpec(NodeKind.SUBTREE, subtree=outer.ref),
            NodeSpec(NodeKind.SUBTREE, subtree=inner_v2.ref),
        ],
    )
    plan = PlanSpec(name="Outer", tree=root, subtrees=[outer, inner, inner_v2])
    return loads_plan(dump_plan(plan))


_TEXT = ParamType.TEXT


def test_nested_subtrees_and_two_versions_of_one_come_back() -> None:
    plan = _nested()
    text = export_xml(plan, {})
    assert '<BehaviorTree ID="Inner_2" _uid="a.inner" _name="Inner" _version="2"' in text
    assert '<SubTree ID="Inner" MSG="{OUT}"' in text
    assert _round_trip(plan) == plan


@pytest.mark.parametrize("name", ["Catch", "Iterator", "Enforce", "Sequence"])
def test_a_tree_never_takes_the_id_of_a_node_model(name: str) -> None:
    """BehaviorTree.CPP refuses a <BehaviorTree ID> that names a registered node."""
    plan = PlanSpec(tree=NodeSpec(NodeKind.WAIT, params={}), name=name)
    xml = export_xml(plan, {})
    assert f'<BehaviorTree ID="{name}"' not in xml
    assert import_xml(xml, "t.xml", {}).name == name


def test_repeat_and_retry_of_minus_1_import_and_come_back() -> None:
    # BehaviorTree.CPP's num_cycles="-1" / num_attempts="-1": no limit (found by the random
    # trees of test_btcpp_random_trees.py, which our import refused)
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        '<RetryUntilSuccessful num_attempts="-1"><Repeat num_cycles="-1"><AlwaysSuccess/>'
        "</Repeat></RetryUntilSuccessful></BehaviorTree></root>"
    )
    written = export_xml(import_xml(text, "forever.xml"), {})
    assert 'num_attempts="-1"' in written and 'num_cycles="-1"' in written
