"""Ports as BehaviorTree.CPP v4 writes them (issue 27 item 4): ``{=}`` (the entry of the
port's own name) and ``{@key}`` (the top-level entry, BehaviorTree.CPP's root blackboard,
from inside a subtree too).
"""

from __future__ import annotations

from capabilities.base import CapabilityRegistry
from engine.btcpp import export_xml, import_xml
from engine.build import build_tree
from engine.instances import ROOT_SCOPE
from engine.spec import Binding, NodeSpec, PlanSpec, SubtreeSpec
from engine.status import SUCCESS
from engine.validation import ERROR, validate_plan

AT_KEY = """<root BTCPP_format="4" main_tree_to_execute="Main">
<BehaviorTree ID="Inner"><Sequence>
  <Action ID="debug__condition" result="{@flag}"/>
  <Action ID="debug__query" value="1;2;3;0;0;0;1" result="{@pose}"/>
  <Script code="@seen := 1"/>
</Sequence></BehaviorTree>
<BehaviorTree ID="Main"><Sequence>
  <Script code="flag := true"/>
  <SubTree ID="Inner"/>
  <Action ID="debug__condition" result="{@flag}"/>
  <Action ID="debug__check_param" value="{pose}" expected="{@pose}"/>
</Sequence></BehaviorTree>
</root>
"""


def _manifests(registry: CapabilityRegistry) -> dict[str, object]:
    return {m.id: m for m in registry.manifests()}


def _walk_ops(spec: PlanSpec) -> list[NodeSpec]:
    found = [n for _, n in spec.walk() if n.op]
    for sub in spec.subtrees:
        found += [n for _, n in sub.tree.walk() if n.op]
    return found


def test_at_key_reads_and_writes_the_top_level_entry_from_a_subtree(
    registry: CapabilityRegistry,
) -> None:
    spec = import_xml(AT_KEY, "at.xml", _manifests(registry))  # type: ignore[arg-type]
    refs = {(n.op, p): b.ref for n in _walk_ops(spec) for p, b in n.params.items() if b.ref}
    assert refs[("debug.condition", "result")] == "@flag"
    assert [p.message for p in validate_plan(spec, registry) if p.severity == ERROR] == []
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(max_ticks=10) is SUCCESS
    assert sorted(tree.blackboard) == ["flag", "pose", "seen"]  # no entry inside the instance


def test_at_key_is_written_back_as_it_was(registry: CapabilityRegistry) -> None:
    manifests = _manifests(registry)
    written = export_xml(import_xml(AT_KEY, "at.xml", manifests), manifests)  # type: ignore[arg-type]
    assert written.count('result="{@flag}"') == 2 and 'result="{@pose}"' in written


def test_at_key_at_the_top_is_checked_as_the_name(registry: CapabilityRegistry) -> None:
    text = AT_KEY.replace('<Script code="flag := true"/>', "")
    spec = import_xml(text, "at.xml", _manifests(registry))  # type: ignore[arg-type]
    errors = [p.message for p in validate_plan(spec, registry) if p.severity == ERROR]
    assert errors == [
        "Nothing sets flag, which 'debug.condition' reads for 'result': add a query that "
        "writes it or declare it as a plan parameter."
    ]


def test_the_scope_of_a_subtree_sends_at_names_to_the_top() -> None:
    instance = NodeSpec.__new__(NodeSpec)
    instance.id, instance.name = "abcdef123", "inner"
    sub = SubtreeSpec(id="s", name="inner", tree=NodeSpec.__new__(NodeSpec))
    inner = ROOT_SCOPE.inside(instance, sub)
    assert inner.key("x") == "inner#abcdef/x"
    assert inner.key("@x") == "x" and ROOT_SCOPE.key("@x") == "x"


def test_eq_is_the_entry_of_the_port_s_own_name(registry: CapabilityRegistry) -> None:
    text = """<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">
      <Sequence><Script code="result := true"/><Action ID="debug__condition" result="{=}"/>
      </Sequence></BehaviorTree></root>"""
    spec = import_xml(text, "eq.xml", _manifests(registry))  # type: ignore[arg-type]
    assert _walk_ops(spec)[0].params["result"] == Binding.reference("result")
    assert build_tree(spec, registry).tick_until_done(max_ticks=5) is SUCCESS


def test_a_subtree_without_a_model_takes_any_type_and_gives_back_what_scripts_write(
    registry: CapabilityRegistry,
) -> None:
    """BehaviorTree.CPP 4.10 ran this to out = 8 (builtins/subtree_eq_remap.xml)."""
    text = """<root BTCPP_format="4" main_tree_to_execute="Main">
    <BehaviorTree ID="Inner"><Script code="out := x * 2"/></BehaviorTree>
    <BehaviorTree ID="Main"><Sequence><Script code="x := 4; out := 0"/>
      <SubTree ID="Inner" x="{=}" out="{=}" n="3"/></Sequence></BehaviorTree></root>"""
    spec = import_xml(text, "eq.xml")
    sub = spec.subtrees[0]
    assert [(p.name, p.type.value) for p in sub.inputs] == [("x", "Any"), ("n", "Any")]
    assert [(p.name, p.type.value) for p in sub.outputs] == [("out", "Any")]
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(max_ticks=5) is SUCCESS
    assert tree.blackboard.get("out") == 8
