"""``costar export-xml`` / ``import-xml`` with the installed capabilities, and XML that
BehaviorTree.CPP 4.10 itself wrote (tests/engine/data/btcpp, see the README there).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest

from capabilities.cli import main
from capabilities.xml_commands import operation_manifests
from engine.btcpp import import_xml
from engine.btcpp.logic import LOGIC
from engine.btcpp.names import decode_id, decode_port
from engine.btcpp.xmltree import parse
from engine.files import load_plan
from engine.operations import Direction, OperationKind
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "resources" / "examples"
BTCPP_DATA = ROOT / "tests" / "engine" / "data" / "btcpp"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name", ["cup_to_bin", "figure3_debug", "nodes/parallel_m_of_n"])
def test_export_then_import_gives_the_same_file(tmp_path: Path, name: str) -> None:
    plan_file = EXAMPLES / f"{name}.costar.json"
    xml, back = tmp_path / "plan.xml", tmp_path / "back.costar.json"
    code, out, err = run_cli("export-xml", str(plan_file), str(xml))
    assert (code, err) == (0, "") and "wrote" in out
    assert 'BTCPP_format="4"' in xml.read_text(encoding="utf-8")
    code, out, err = run_cli("import-xml", str(xml), str(back))
    assert (code, err) == (0, "")
    assert back.read_bytes() == plan_file.read_bytes()


def test_import_lists_every_unknown_node_with_its_line(tmp_path: Path) -> None:
    xml = tmp_path / "foreign.xml"
    xml.write_text(
        '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Sequence>\n'
        '<motion__move_to target="0;0;0.5;1;0;0;0" _types="target=Pose"/>\n'
        "<OpenGripper/>\n<motion__fly/>\n</Sequence>\n</BehaviorTree>\n</root>\n",
        encoding="utf-8",
    )
    out_file = tmp_path / "out.costar.json"
    code, _, err = run_cli("import-xml", str(xml), str(out_file))
    assert code == 2 and not out_file.exists()
    assert err.splitlines() == [
        f"error: {xml}: line 5: expected a node type this program knows (a mapped "
        "BehaviorTree.CPP node, Iterator, Enforce, SubTree or an operation), got unknown "
        "node type 'OpenGripper'",
        f"error: {xml}: line 6: expected a node type this program knows (a mapped "
        "BehaviorTree.CPP node, Iterator, Enforce, SubTree or an operation), got unknown "
        "node type 'motion__fly'",
    ]


def test_the_smallest_v4_file_imports_and_runs_to_success(tmp_path: Path) -> None:
    xml, plan_file = tmp_path / "smallest.xml", tmp_path / "smallest.costar.json"
    xml.write_text(
        '<root BTCPP_format="4">\n<BehaviorTree ID="MainTree">\n'
        "<Sequence><AlwaysSuccess/></Sequence>\n</BehaviorTree>\n</root>\n",
        encoding="utf-8",
    )
    code, out, err = run_cli("import-xml", str(xml), str(plan_file))
    assert (code, err) == (0, "") and "wrote" in out
    code, out, err = run_cli("run", "--cell", "none", "--no-record", str(plan_file))
    assert (code, err) == (0, "")
    assert out.strip().endswith("SUCCESS after 1 ticks")


def test_export_errors_name_the_file(tmp_path: Path) -> None:
    broken = tmp_path / "broken.costar.json"
    broken.write_text("{", encoding="utf-8")
    code, _, err = run_cli("export-xml", str(broken), str(tmp_path / "x.xml"))
    assert code == 2 and "broken.costar.json" in err
    code, _, err = run_cli("export-xml", str(tmp_path / "missing.costar.json"), "x.xml")
    assert code == 2 and "missing.costar.json" in err


def test_btcpp_tree_nodes_model_declares_our_operations_as_we_read_them() -> None:
    """tree_nodes_model.xml is BehaviorTree.CPP's writeTreeNodesModelXML of a factory that
    registered our operations with their ports: each model is read back as the operation.

    A subset check: the file pins what BehaviorTree.CPP wrote for the operations it was
    given, so an operation added since needs no new file (it is not in it); every model
    in it must still be an operation of ours with the same kind and ports. The ports' docs
    are prose BehaviorTree.CPP copied from ours: a doc reworded since is no mismatch, only a
    port's presence is (it is written at all, as a description).
    """
    root = parse((BTCPP_DATA / "tree_nodes_model.xml").read_text(encoding="utf-8"))
    models = root.children[0].children
    manifests = operation_manifests()
    custom = {logic.model for logic in LOGIC.values() if not logic.builtin}  # Iterator, Catch...
    ours = [m for m in models if m.attrs["ID"] not in custom]
    assert {m.attrs["ID"] for m in models} >= custom
    assert len(ours) >= 50  # the file covers the operations of its day
    for model in ours:
        assert decode_id(model.attrs["ID"]) in manifests, model.attrs["ID"]
        manifest = manifests[decode_id(model.attrs["ID"])]
        assert (model.tag == "Condition") == (manifest.kind is OperationKind.CONDITION)
        ports = {decode_port(port.attrs["name"]): port for port in model.children}
        assert set(ports) == {p.name for p in manifest.ports}
        for spec in manifest.ports:
            direction = "output_port" if spec.direction is Direction.OUT else "input_port"
            assert ports[spec.name].tag == direction
            assert bool(ports[spec.name].text) == bool(spec.doc)


def test_a_tree_over_btcpp_written_models_imports_with_their_types() -> None:
    model = (BTCPP_DATA / "tree_nodes_model.xml").read_text(encoding="utf-8")
    tree = (
        '<BehaviorTree ID="T"><Sequence>'
        '<motion__move_to target="{CUP_POSE}" speed="0.5" mode="linear"/>'
        '<Enforce count="3"><markers__object_found object="cup"/></Enforce>'
        "</Sequence></BehaviorTree>"
    )
    plan = import_xml(model.replace("<TreeNodesModel>", tree + "<TreeNodesModel>"), "m.xml")
    assert plan.tree is not None
    move, enforce = plan.tree.children
    assert move.op == "motion.move_to"
    assert move.params == {
        "target": Binding.reference("CUP_POSE"),
        "speed": Binding.fixed(0.5, ParamType.NUMBER),  # BehaviorTree.CPP's "double"
        "mode": Binding.fixed("linear", ParamType.TEXT),  # its "std::string"
    }
    assert enforce.kind is NodeKind.ENFORCE
    assert enforce.params["count"] == Binding.fixed(3.0, ParamType.NUMBER)
    assert enforce.children[0].op == "markers.object_found"


def _shape(
    node: NodeSpec, defaults_of: dict[str, Any] | None = None, plan: PlanSpec | None = None
) -> Any:
    """Kind, operation (or subtree name), bindings and children; with ``defaults_of``
    (manifests), a fixed binding equal to its port's default counts as unbound
    (BehaviorTree.CPP writes them).
    """
    params = dict(node.params)
    if plan is not None and node.subtree is not None:
        sub = plan.subtree(node.subtree)
        return (node.kind, sub.name if sub is not None else None, params)
    manifest = (defaults_of or {}).get(node.op or "")
    for port in manifest.ports if manifest is not None else ():
        if params.get(port.name) == Binding.fixed(port.default, port.type):
            del params[port.name]
    children = [_shape(child, defaults_of, plan) for child in node.children]
    return (node.kind, node.op, params, children)


def test_a_tree_btcpp_wrote_after_loading_our_export_imports_as_the_plan() -> None:
    """cup_to_bin_written_by_btcpp.xml: our export of cup_to_bin (the Figure 3 plan of
    operation leaves it was then, kept beside it) loaded by BehaviorTree.CPP 4.10 and written
    back with its WriteTreeToXML (its names, no _uid, its own model).
    """
    written = (BTCPP_DATA / "cup_to_bin_written_by_btcpp.xml").read_text(encoding="utf-8")
    assert "_uid" not in written
    manifests = operation_manifests()
    plan = import_xml(written, "written.xml", manifests)
    original = load_plan(BTCPP_DATA / "cup_to_bin.costar.json")
    assert plan.tree is not None and original.tree is not None
    assert _shape(plan.tree, manifests) == _shape(original.tree, manifests)
    assert [n.name for _, n in plan.walk()] == [n.name for _, n in original.walk()]


def test_a_plan_with_subtrees_btcpp_wrote_imports_with_the_remapping() -> None:
    """kitting_written_by_btcpp.xml: our export of the kitting plan loaded and written back by
    BehaviorTree.CPP 4.10, which keeps one BehaviorTree per instance and no SubTree models:
    the subtrees' ports come from the remapping and the operations inside.
    """
    written = (BTCPP_DATA / "kitting_written_by_btcpp.xml").read_text(encoding="utf-8")
    manifests = operation_manifests()
    plan = import_xml(written, "kitting.xml", manifests)
    original = load_plan(EXAMPLES / "kitting.costar.json")
    assert plan.tree is not None and original.tree is not None
    assert _shape(plan.tree, manifests, plan) == _shape(original.tree, manifests, original)
    assert sorted(s.name for s in plan.subtrees) == sorted(s.name for s in original.subtrees)
    for sub in plan.subtrees:
        mine = next(s for s in original.subtrees if s.name == sub.name)
        assert _shape(sub.tree, manifests, plan) == _shape(mine.tree, manifests, original)
        # a port every instance leaves to its default is not in BehaviorTree.CPP's output
        used = {p for _, n in original.walk() if n.subtree == mine.ref for p in n.params}
        expected_in = {(p.name, p.type) for p in mine.inputs if p.name in used}
        assert {(p.name, p.type) for p in sub.inputs} == expected_in
        assert {(p.name, p.type) for p in sub.outputs} == {
            (p.name, p.type) for p in mine.outputs if p.name in used
        }
