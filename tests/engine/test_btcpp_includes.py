"""``<include path=...>`` and the choice of the main tree, as BehaviorTree.CPP 4.10 reads a
file (src/xml_parsing.cpp, src/bt_factory.cpp).

The three files below, read by BehaviorTree.CPP 4.10's createTreeFromFile (and by
tools/btcpp/run_xml.cpp from their folder), run to SUCCESS with n = 11.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from engine.btcpp import XmlFileError, import_xml, load_xml
from engine.build import build_tree
from engine.spec import NodeKind
from engine.status import SUCCESS

MAIN = """<root BTCPP_format="4">
  <include path="sub/grasp.xml"/>
  <BehaviorTree ID="Main">
    <Sequence>
      <Script code="n:=0"/>
      <SubTree ID="Grasp" _autoremap="true"/>
      <SubTree ID="Count" _autoremap="true"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
GRASP = """<root BTCPP_format="4">
  <include path="../common.xml"/>
  <BehaviorTree ID="Grasp">
    <Sequence>
      <Script code="n+=1"/>
      <AlwaysSuccess/>
    </Sequence>
  </BehaviorTree>
</root>
"""
COMMON = """<root BTCPP_format="4">
  <BehaviorTree ID="Count">
    <Script code="n+=10"/>
  </BehaviorTree>
</root>
"""


def _files(folder: Path, main: str = MAIN) -> Path:
    (folder / "sub").mkdir()
    (folder / "sub" / "grasp.xml").write_text(GRASP, encoding="utf-8")
    (folder / "common.xml").write_text(COMMON, encoding="utf-8")
    path = folder / "main.xml"
    path.write_text(main, encoding="utf-8")
    return path


def test_included_trees_are_read_relative_to_the_including_file_and_run(
    tmp_path: Path, registry: CapabilityRegistry, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir("/")  # a file's includes do not depend on the working folder
    plan = load_xml(_files(tmp_path))
    assert plan.tree is not None and plan.tree.kind is NodeKind.SEQUENCE  # Main, its own tree
    assert sorted(s.id for s in plan.subtrees) == ["Count", "Grasp"]
    tree = build_tree(plan, registry)
    status = tree.tick()
    while status.value == "RUNNING":
        status = tree.tick()
    assert status is SUCCESS
    assert tree.blackboard.get("n") == 11  # as BehaviorTree.CPP 4.10 ends it


def test_a_text_takes_its_includes_from_the_working_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _files(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert import_xml(MAIN, "main.xml").name == "Main"
    monkeypatch.chdir("/")
    with pytest.raises(XmlFileError) as caught:
        import_xml(MAIN, "main.xml")
    first, *then = caught.value.problems
    assert first.line == 2 and "sub/grasp.xml" in first.expected
    assert {p.got for p in then} == {"'Grasp'", "'Count'"}  # the subtrees it would have brought


@pytest.mark.parametrize(
    ("include", "expected"),
    [
        ("<include/>", "an <include> with a path attribute"),
        ('<include path="missing.xml"/>', "a readable file for <include path='missing.xml'>"),
        ('<include path="main.xml"/>', "includes without a cycle"),
        ('<include path="common.xml" ros_pkg="grasping"/>', "without ros_pkg"),
        ('<include path="bad.xml"/>', "well-formed XML in bad.xml"),
    ],
)
def test_a_bad_include_is_a_problem_at_its_line(
    tmp_path: Path, include: str, expected: str
) -> None:
    (tmp_path / "bad.xml").write_text("<root><BehaviorTree></root>", encoding="utf-8")
    main = MAIN.replace('<include path="sub/grasp.xml"/>', include)
    for tree in ("Grasp", "Count"):
        main = main.replace(f'<SubTree ID="{tree}" _autoremap="true"/>', "")
    with pytest.raises(XmlFileError) as caught:
        load_xml(_files(tmp_path, main))
    assert [(p.line, expected in p.expected) for p in caught.value.problems] == [(2, True)]


def test_the_tree_run_is_the_one_named_else_the_files_own_else_its_first(tmp_path: Path) -> None:
    two = """<root BTCPP_format="4">
  <BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>
  <BehaviorTree ID="B"><AlwaysFailure/></BehaviorTree>
</root>"""
    first = import_xml(two, "two.xml")  # as BehaviorTree.CPP writes a tree: the main first
    assert first.tree is not None and first.tree.kind is NodeKind.ALWAYS_SUCCESS
    named = two.replace('BTCPP_format="4"', 'BTCPP_format="4" main_tree_to_execute="B"')
    plan = import_xml(named, "two.xml")
    assert plan.tree is not None and plan.tree.kind is NodeKind.ALWAYS_FAILURE
    assert load_xml(_files(tmp_path)).name == "Main"  # its own, after the included ones
