"""Plan files: round trips, deterministic bytes, every class of bad file, atomic save."""

from __future__ import annotations

import json
import os
import random
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from bt_fakes import settings

from engine import plan_writer
from engine.files import (
    MAX_TREE_DEPTH,
    PlanFileError,
    dump_plan,
    load_plan,
    loads_plan,
    save_plan,
)
from engine.spec import Binding, NodeKind, NodeLayout, NodeSpec, ParameterDecl, PlanSpec, RunPolicy
from engine.types import (
    JointConfig,
    ObjectModel,
    ParamType,
    Pose,
    Region,
    Waypoint,
    WaypointFrame,
)

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = json.loads((ROOT / "resources" / "schemas" / "plan.schema.json").read_text("utf-8"))
DATA = Path(__file__).resolve().parent / "data"

POSE = Pose((0.4, -0.25, 0.1), (0.0, 0.0, 0.7071067811865476, 0.7071067811865476))
VALUES: dict[ParamType, Any] = {
    ParamType.POSE: POSE,
    ParamType.JOINTS: JointConfig((0.0, -1.5707963267948966, 1.2, 0.0, 1.5, 0.1)),
    ParamType.OBJECT: ObjectModel("cup"),
    ParamType.REGION: Region((0.5, 0.0, 0.2), 0.3),
    ParamType.WAYPOINT: Waypoint("above_cup", WaypointFrame.OBJECT, POSE, None, "cup"),
    ParamType.NUMBER: 0.1 + 0.2,
    ParamType.TEXT: 'größer als 3 "mm"',
    ParamType.BOOL: True,
    ParamType.DURATION: 2.5,
    ParamType.ANY: {"free": [1, "two", None]},
}
WAYPOINTS = [
    Waypoint("home", WaypointFrame.WORLD, Pose((0.3, 0.1, 0.5))),
    Waypoint("grasp", WaypointFrame.OBJECT, POSE, reference="cup"),
    Waypoint("marker_1", WaypointFrame.MARKER, POSE, reference="aruco:7"),
    Waypoint("park", WaypointFrame.JOINTS, joints=JointConfig((0.0, -1.0, 1.0, 0.0, 0.5, 0.0))),
]


def full_plan() -> PlanSpec:
    """A plan that uses every part of the format."""
    ops = [
        NodeSpec(
            NodeKind.OPERATION,
            f"set {ptype.value}",
            op="test.take",
            params={"value": Binding.fixed(value, ptype)},
        )
        for ptype, value in VALUES.items()
    ]
    find = NodeSpec(
        NodeKind.OPERATION,
        "find cup",
        op="test.find",
        params={
            "model": Binding.fixed(ObjectModel("cup"), ParamType.OBJECT),
            "pose": Binding.reference("CUP_POSE"),
        },
    )
    move = NodeSpec(
        NodeKind.OPERATION, op="test.move_to", params={"target": Binding.reference("CUP_POSE")}
    )
    retry = NodeSpec(NodeKind.RETRY, params=settings(NodeKind.RETRY, count=3), children=[move])
    wait = NodeSpec(NodeKind.WAIT, "pause", params=settings(NodeKind.WAIT, seconds=0.5))
    parallel = NodeSpec(
        NodeKind.PARALLEL,
        params=settings(NodeKind.PARALLEL, success="any", failure=2),
        children=[wait],
    )
    tree = NodeSpec(NodeKind.SEQUENCE, "Transfer", children=[*ops, find, retry, parallel])
    return PlanSpec(
        tree=tree,
        name="Figure 3",
        description="Pick up the cup.\nSecond line.",
        run_policy=RunPolicy.UNTIL_SUCCESS,
        parameters=[
            *(ParameterDecl(f"P_{t.name}", t, v, doc=f"a {t.value}") for t, v in VALUES.items()),
            ParameterDecl("CUP_POSE", ParamType.POSE),
        ],
        waypoints=list(WAYPOINTS),
        objects=["cup", "waste_bin"],
        layout={tree.id: NodeLayout(10.0, -20.5, False), move.id: NodeLayout(3, 4, True)},
    )


def node_doc(node_id: str, kind: str, **extra: Any) -> dict[str, Any]:
    return {"id": node_id, "kind": kind, **extra}


def plan_doc(tree: Any = None, **extra: Any) -> dict[str, Any]:
    return {"format": "costar-plan", "format_version": 2, "tree": tree, **extra}


def root(plan: PlanSpec) -> NodeSpec:
    """The plan's tree, which these tests know is there."""
    assert plan.tree is not None
    return plan.tree


def error_of(text: str, **kwargs: Any) -> PlanFileError:
    with pytest.raises(PlanFileError) as info:
        loads_plan(text, "figure3.costar.json", **kwargs)
    return info.value


# --------------------------------------------------------------------------- round trips


def test_round_trip_keeps_everything() -> None:
    plan = full_plan()
    loaded = loads_plan(dump_plan(plan))
    assert loaded == plan
    assert loaded.parameters[1].value == VALUES[ParamType.JOINTS]
    assert loaded.waypoints == WAYPOINTS
    assert loaded.layout[root(plan).children[-2].children[0].id].collapsed is True


def test_save_load_save_is_byte_identical(tmp_path: Path) -> None:
    first, second = tmp_path / "a.costar.json", tmp_path / "b.costar.json"
    save_plan(full_plan(), first)
    save_plan(load_plan(first), second)
    assert first.read_bytes() == second.read_bytes()
    text = first.read_text("utf-8")
    assert text.endswith("}\n") and '\n  "format_version": 2,' in text
    assert "0.30000000000000004" in text  # floats as repr
    assert "größer" in text  # UTF-8, not escapes


def test_random_poses_are_byte_identical_after_one_save() -> None:
    rng = random.Random(7)
    for _ in range(300):
        q = [rng.uniform(-1.0, 1.0) for _ in range(4)]
        pose = Pose.of((rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 1)), q)
        plan = PlanSpec(parameters=[ParameterDecl("P", ParamType.POSE, pose)])
        text = dump_plan(plan)
        assert dump_plan(loads_plan(text)) == text


def test_output_order_is_canonical() -> None:
    plan = full_plan()
    node = root(plan).children[0]
    node.params = {"b": Binding.reference("B"), "a": Binding.reference("A")}
    again = loads_plan(dump_plan(plan))
    assert list(root(again).children[0].params) == ["a", "b"]
    # layout in tree order, whatever order the editor inserted it in
    before = dump_plan(plan)
    plan.layout = dict(reversed(plan.layout.items()))
    assert dump_plan(plan) == before
    doc = json.loads(before)
    assert list(doc["layout"]["nodes"]) == [root(plan).id, root(plan).children[-2].children[0].id]


def test_whole_numbers_are_written_as_read_back() -> None:
    node = NodeSpec(NodeKind.OPERATION, op="t", params={"n": Binding.fixed(2, ParamType.NUMBER)})
    plan = PlanSpec(tree=node, parameters=[ParameterDecl("D", ParamType.DURATION, 3)])
    text = dump_plan(plan)
    assert '"value": 2.0' in text and '"value": 3.0' in text
    assert dump_plan(loads_plan(text)) == text


def test_empty_bindings_are_left_out() -> None:
    node = NodeSpec(NodeKind.OPERATION, op="test.move_to", params={"target": Binding()})
    assert "params" not in json.loads(dump_plan(PlanSpec(tree=node)))["tree"]


def test_empty_plan_and_defaults() -> None:
    plan = PlanSpec(id="p1")
    doc = json.loads(dump_plan(plan))
    assert doc["tree"] is None and doc["layout"] == {"nodes": {}}
    minimal = loads_plan('{"format": "costar-plan", "format_version": 1}')
    assert minimal.tree is None and minimal.run_policy is RunPolicy.ONCE and minimal.id
    assert minimal.give_up_after == 5  # files written before the limit get the default
    assert "give_up_after" not in doc  # the default is not written: old files round-trip


def test_the_limit_of_identical_failures_round_trips() -> None:
    for limit in (0, 1, 12):
        plan = PlanSpec(id="p1", run_policy=RunPolicy.UNTIL_SUCCESS, give_up_after=limit)
        text = dump_plan(plan)
        assert json.loads(text)["give_up_after"] == limit
        assert loads_plan(text).give_up_after == limit


def test_half_built_plans_load() -> None:
    """The editor saves work in progress: an empty decorator or composite is for validation."""
    tree = node_doc(
        "s", "sequence", children=[node_doc("i", "inverter"), node_doc("p", "parallel")]
    )
    plan = loads_plan(json.dumps(plan_doc(tree)))
    assert [c.kind for c in root(plan).children] == [NodeKind.INVERTER, NodeKind.PARALLEL]


def test_text_is_never_executed() -> None:
    evil = "__import__('os').system('false')"
    tree = node_doc("a", "operation", op=evil, params={"x": {"type": "Any", "value": evil}})
    plan = loads_plan(json.dumps(plan_doc(tree)))
    assert root(plan).op == evil and root(plan).params["x"].value == evil


# --------------------------------------------------------------------------- aliases


def test_renamed_operations_load_under_their_new_id() -> None:
    tree = node_doc("s", "sequence", children=[
        node_doc("a", "operation", op="old.move"),
        node_doc("b", "operation", op="older.move"),
        node_doc("c", "operation", op="loop.a"),
    ])  # fmt: skip
    aliases = {
        "old.move": "motion.move_to",
        "older.move": "old.move",
        "loop.a": "loop.b",
        "loop.b": "loop.a",
    }
    plan = loads_plan(json.dumps(plan_doc(tree)), aliases=aliases)
    assert [c.op for c in root(plan).children] == ["motion.move_to", "motion.move_to", "loop.b"]
    assert '"old.move"' not in dump_plan(plan)


def test_renamed_kinds_load() -> None:
    tree = node_doc(
        "f",
        "fallback",
        children=[node_doc("r", "reactive_fallback", children=[node_doc("w", "wait")])],
    )
    plan = loads_plan(json.dumps(plan_doc(tree)))
    assert root(plan).kind is NodeKind.SELECTOR
    assert root(plan).children[0].kind is NodeKind.REACTIVE_SELECTOR
    assert '"selector"' in dump_plan(plan) and "fallback" not in dump_plan(plan)


# --------------------------------------------------------------------------- bad files

OP = node_doc("op1", "operation", op="test.move_to")
BAD: list[tuple[str, Any, str, str]] = [
    ("not an object", [], "$", "costar-plan object"),
    ("other format", {"format": "word", "format_version": 1}, "$.format", "'costar-plan'"),
    ("no version", {"format": "costar-plan"}, "$.format_version", "versions 1"),
    ("newer version", plan_doc(format_version=5), "$.format_version", "newer CoSTAR Instructor"),
    ("version as text", plan_doc(format_version="1"), "$.format_version", "versions 1"),
    ("unknown top field", plan_doc(trea=None), "$.trea", "one of the fields format"),
    ("name a number", plan_doc(name=3), "$.name", "a text"),
    ("bad run policy", plan_doc(run_policy="twice"), "$.run_policy", "once, until_success, forever"),
    ("negative limit", plan_doc(give_up_after=-1), "$.give_up_after", "0 or more"),
    ("limit as text", plan_doc(give_up_after="5"), "$.give_up_after", "whole number"),
    ("tree a list", plan_doc([]), "$.tree", "an object with id, kind"),
    ("unknown node field", plan_doc(node_doc("a", "wait", kidn=1)), "$.tree.kidn", "one of the fields id"),
    ("missing kind", plan_doc({"id": "a"}), "$.tree.kind", "required"),
    ("unknown kind", plan_doc(node_doc("a", "sequense")), "$.tree.kind", "sequence, selector"),
    ("empty id", plan_doc(node_doc(" ", "wait")), "$.tree.id", "non-empty text"),
    ("duplicate ids", plan_doc(node_doc("a", "sequence", children=[node_doc("b", "wait"), node_doc("a", "wait")])),
     "$.tree.children[1].id", "already the id of $.tree"),
    ("operation without op", plan_doc(node_doc("a", "operation")), "$.tree.op", "operation id"),
    ("op on a wait", plan_doc(node_doc("a", "wait", op="x")), "$.tree.op", "only operation nodes"),
    ("op on a sequence", plan_doc(node_doc("a", "sequence", op="debug.succeed")), "$.tree.op", "only operation"),
    ("children not a list", plan_doc(node_doc("a", "sequence", children={})), "$.tree.children", "a list of nodes"),
    ("leaf with children", plan_doc(node_doc("a", "sequence", children=[{**OP, "children": [node_doc("b", "wait")]}])),
     "$.tree.children[0].children", "a leaf"),
    ("two children under a decorator", plan_doc(node_doc("a", "inverter", children=[OP, node_doc("b", "wait")])),
     "$.tree.children", "at most one child"),
    ("wrong pose", plan_doc({**OP, "params": {"target": {"type": "Pose", "value": "CUP"}}}),
     "$.tree.params.target.value", "position, orientation"),
    ("pose missing orientation", plan_doc({**OP, "params": {"target": {"type": "Pose", "value": {"position": [0, 0, 0]}}}}),
     "$.tree.params.target.value.orientation", "missing"),
    ("both fixed and ref", plan_doc({**OP, "params": {"target": {"type": "Text", "value": "a", "ref": "A"}}}),
     "$.tree.params.target", "not both"),
    ("binding without value", plan_doc({**OP, "params": {"target": {"type": "Pose"}}}), "$.tree.params.target", "fixed value"),
    ("unknown type", plan_doc({**OP, "params": {"target": {"type": "Posture", "value": 1}}}),
     "$.tree.params.target.type", "Pose, JointConfig"),
    ("empty ref", plan_doc({**OP, "params": {"target": {"ref": ""}}}), "$.tree.params.target.ref", "non-empty"),
    ("odd port name", plan_doc({**OP, "params": {"a b": 1}}), '$.tree.params["a b"]', "an object with"),
    ("config list", plan_doc(node_doc("a", "wait", config={"seconds": [1]}), format_version=1), "$.tree.config.seconds", "a number"),
    ("config in version 2", plan_doc(node_doc("a", "wait", config={"seconds": 1})), "$.tree.config", "one of the fields"),
    ("parameter bad value", plan_doc(parameters=[{"name": "N", "type": "Number", "value": "3"}]),
     "$.parameters[0].value", "finite number"),
    ("parameter twice", plan_doc(parameters=[{"name": "N", "type": "Bool"}, {"name": "N", "type": "Bool"}]),
     "$.parameters[1].name", "not used before"),
    ("parameter field", plan_doc(parameters=[{"name": "N", "type": "Bool", "default": 1}]),
     "$.parameters[0].default", "one of the fields"),
    ("waypoint joints without joints", plan_doc(waypoints=[{"name": "w", "frame": "joints"}]), "$.waypoints[0]", "joints"),
    ("waypoint bad frame", plan_doc(waypoints=[{"name": "w", "frame": "tool"}]), "$.waypoints[0].frame", "world"),
    ("waypoint twice", plan_doc(waypoints=[{"name": "w", "frame": "joints", "joints": [0]}] * 2),
     "$.waypoints[1].name", "not used before"),
    ("object a number", plan_doc(objects=["cup", 3]), "$.objects[1]", "non-empty text"),
    ("layout field", plan_doc(layout={"zoom": 1}), "$.layout.zoom", "one of the fields nodes"),
    ("layout x text", plan_doc(layout={"nodes": {"n1": {"x": "1", "y": 2}}}), "$.layout.nodes.n1.x", "finite number"),
    ("layout collapsed", plan_doc(layout={"nodes": {"9-x": {"x": 1, "y": 2, "collapsed": 1}}}),
     '$.layout.nodes["9-x"].collapsed', "true or false"),
]  # fmt: skip


@pytest.mark.parametrize(("doc", "path", "expected"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_documents_name_the_path(doc: Any, path: str, expected: str) -> None:
    error = error_of(json.dumps(doc))
    assert error.json_path == path
    assert expected in str(error)
    assert str(error).startswith(f"figure3.costar.json: {path}: expected ")


def test_message_reads_like_the_design() -> None:
    doc = plan_doc(
        node_doc(
            "s",
            "sequence",
            children=[
                OP,
                {**OP, "id": "op2", "params": {"target": {"type": "Pose", "value": [1, 2]}}},
            ],
        )
    )
    message = str(error_of(json.dumps(doc)))
    assert message.startswith(
        "figure3.costar.json: $.tree.children[1].params.target.value: expected an object"
    )
    assert message.endswith("got list [1, 2]")


@pytest.mark.parametrize(
    ("name", "line", "column", "got"),
    [
        ("truncated.costar.json", 9, 1, "the end of the file: it is cut off"),
        ("trailing_comma.costar.json", 6, 3, "a syntax error (Expecting value)"),
    ],
)
def test_invalid_json_gives_line_and_column(name: str, line: int, column: int, got: str) -> None:
    with pytest.raises(PlanFileError) as info:
        load_plan(DATA / name)
    assert info.value.got == got
    assert (info.value.line, info.value.column) == (line, column)
    given = DATA / name  # the error names the file as given, not only its base name
    assert str(info.value).startswith(f"{given}: line {line} column {column}: expected valid JSON")


def test_data_files_of_newer_version_and_duplicate_keys() -> None:
    with pytest.raises(
        PlanFileError, match=r"newer_version.costar.json: \$.format_version: .*reads \(1, 2, 3, 4\)"
    ):
        load_plan(DATA / "newer_version.costar.json")
    with pytest.raises(PlanFileError) as info:
        load_plan(DATA / "duplicate_key.costar.json")
    assert info.value.json_path == "$.tree.children[0]" and "'kind' twice" in str(info.value)


def test_nan_is_refused_both_ways() -> None:
    assert "NaN" in str(error_of('{"format": "costar-plan", "format_version": 1, "name": NaN}'))
    plan = PlanSpec(parameters=[ParameterDecl("N", ParamType.NUMBER, float("nan"))])
    with pytest.raises(PlanFileError, match="finite numbers"):
        dump_plan(plan)


def test_unreadable_files_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(
        PlanFileError, match=r"missing.costar.json: expected a plan file, got no file"
    ):
        load_plan(tmp_path / "missing.costar.json")
    with pytest.raises(PlanFileError, match=r"folder.costar.json: expected a readable plan file"):
        (tmp_path / "folder.costar.json").mkdir()
        load_plan(tmp_path / "folder.costar.json")
    binary = tmp_path / "binary.costar.json"
    binary.write_bytes(b'{"name": "\xff"}')
    with pytest.raises(PlanFileError, match=r"binary.costar.json: expected UTF-8 text"):
        load_plan(binary)


# --------------------------------------------------------------------------- atomic save


@pytest.mark.parametrize("failing", ["fsync", "replace"])
def test_failed_save_leaves_the_old_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, failing: str
) -> None:
    target = tmp_path / "plan.costar.json"
    save_plan(PlanSpec(name="old"), target)
    before = target.read_bytes()

    def broken(*args: Any) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(plan_writer.os, failing, broken)
    with pytest.raises(
        PlanFileError,
        match=r"plan\.costar\.json: expected a place where the plan can be written, got No space",
    ):
        save_plan(PlanSpec(name="new"), target)
    monkeypatch.undo()
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plan.costar.json"]  # no temp file left


def test_save_keeps_permissions_and_refuses_missing_folder(tmp_path: Path) -> None:
    target = tmp_path / "plan.costar.json"
    save_plan(PlanSpec(), target)
    os.chmod(target, 0o640)
    save_plan(PlanSpec(name="again"), target)
    assert target.stat().st_mode & 0o777 == 0o640
    with pytest.raises(PlanFileError, match=r"nowhere\.costar\.json"):
        save_plan(PlanSpec(), tmp_path / "no" / "nowhere.costar.json")


# --------------------------------------------------------------------------- size and depth


def chain(depth: int) -> NodeSpec:
    node = NodeSpec(NodeKind.WAIT, params=settings(NodeKind.WAIT, seconds=0))
    for _ in range(depth - 1):
        node = NodeSpec(NodeKind.INVERTER, children=[node])
    return node


def test_deep_plan_round_trips() -> None:
    plan = PlanSpec(tree=chain(300))
    text = dump_plan(plan)
    loaded = loads_plan(text)  # (== on specs this deep would itself recurse too far)
    assert [n.id for _, n in loaded.walk()] == [n.id for _, n in plan.walk()]
    assert dump_plan(loaded) == text
    with pytest.raises(PlanFileError, match=f"at most {MAX_TREE_DEPTH} levels"):
        dump_plan(PlanSpec(tree=chain(MAX_TREE_DEPTH + 1)))
    tree: dict[str, Any] = {"id": "leaf", "kind": "wait"}
    for index in range(MAX_TREE_DEPTH):
        tree = {"id": f"n{index}", "kind": "inverter", "children": [tree]}
    assert "levels deep" in str(error_of(json.dumps(plan_doc(tree))))
    assert "levels deep" in str(error_of("[" * 5000 + "]" * 5000))


def test_thousand_node_plan_is_fast() -> None:
    ops = [
        NodeSpec(
            NodeKind.OPERATION,
            f"move {i}",
            op="test.move_to",
            params={"target": Binding.fixed(POSE, ParamType.POSE)},
        )
        for i in range(999)
    ]
    plan = PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, children=ops))
    plan.layout = {n.id: NodeLayout(i, i) for i, n in enumerate(ops)}
    text = dump_plan(plan)
    loaded = loads_plan(text)  # its speed is bench's to measure, never a test's
    assert len(root(loaded).children) == 999
    assert loaded.layout == plan.layout


# --------------------------------------------------------------------------- schema


def schema_errors(doc: Any) -> list[str]:
    validator = jsonschema.Draft202012Validator(SCHEMA)
    return [f"{e.json_path}: {e.message}" for e in validator.iter_errors(doc)]


def test_schema_is_valid_and_accepts_examples_and_dumped_plans() -> None:
    jsonschema.Draft202012Validator.check_schema(SCHEMA)
    examples = sorted((ROOT / "resources" / "examples").rglob("*.costar.json"))
    docs = [json.loads(p.read_text("utf-8")) for p in examples]
    docs += [json.loads(dump_plan(p)) for p in (full_plan(), PlanSpec(), PlanSpec(tree=chain(20)))]
    for doc in docs:
        assert schema_errors(doc) == []
    for example in examples:  # and every example loads
        load_plan(example)


# Uniqueness across a document is beyond JSON Schema; the reader checks it.
# The schema describes format 2 only; version-1 documents are the reader's business.
SCHEMA_BAD = [
    b
    for b in BAD
    if b[0] not in ("duplicate ids", "parameter twice", "waypoint twice", "config list")
]


@pytest.mark.parametrize(
    ("doc", "path"), [b[1:3] for b in SCHEMA_BAD], ids=[b[0] for b in SCHEMA_BAD]
)
def test_schema_refuses_what_the_reader_refuses(doc: Any, path: str) -> None:
    assert schema_errors(doc), f"the schema accepts a document the reader refuses at {path}"


def test_the_scene_a_plan_was_taught_on_round_trips(tmp_path: Path) -> None:
    plan = PlanSpec(
        NodeSpec(NodeKind.WAIT, params={"seconds": Binding.fixed(1.0, ParamType.DURATION)})
    )
    plan.scene = "kitting_handoff"
    path = tmp_path / "scene.costar.json"
    save_plan(plan, path)
    assert '"scene": "kitting_handoff"' in path.read_text(encoding="utf-8")
    assert load_plan(path).scene == "kitting_handoff"
    plan.scene = ""
    save_plan(plan, path)
    assert '"scene"' not in path.read_text(encoding="utf-8")
