"""The port defaults of a file's TreeNodesModel for a SubTree (issue 27 item 4), as
BehaviorTree.CPP 4.10's src/xml_parsing.cpp applies them: a port an instance leaves out
takes its model's default (``{key}``: remapped to that entry, any direction), a port with no
default must be remapped, and an untyped port's constant is an
integer, a real or a text as BehaviorTree.CPP stores it.
"""

from __future__ import annotations

import pytest

from capabilities.base import CapabilityRegistry
from engine.btcpp import XmlFileError, export_xml, import_xml
from engine.build import build_tree
from engine.spec import Binding, PlanSpec
from engine.status import SUCCESS
from engine.types import ParamType


def _file(model: str, inner: str, main: str) -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<TreeNodesModel><SubTree ID="Inner">{model}</SubTree></TreeNodesModel>'
        f'<BehaviorTree ID="Inner">{inner}</BehaviorTree>'
        f'<BehaviorTree ID="Main"><Sequence>{main}</Sequence></BehaviorTree></root>'
    )


DEFAULTS = _file(
    '<input_port name="a" default="5"/><input_port name="b" default="{src}"/>'
    '<output_port name="c" default="{dst}"/><input_port name="d" default="7"/>',
    '<Script code="c := a + b + d"/>',
    '<Script code="src := 10; dst := 0"/><SubTree ID="Inner" d="1"/>',
)


def _instance(spec: PlanSpec) -> dict[str, Binding]:
    return next(node for _, node in spec.walk() if node.subtree is not None).params


def _run(registry: CapabilityRegistry, spec: PlanSpec) -> dict[str, object]:
    tree = build_tree(spec, registry)
    assert tree.tick_until_done(max_ticks=10) is SUCCESS
    return {key: tree.blackboard.get(key) for key in tree.blackboard if "/" not in key}


def test_left_out_ports_take_their_model_defaults(registry: CapabilityRegistry) -> None:
    spec = import_xml(DEFAULTS, "defaults.xml")
    params = _instance(spec)
    assert params["b"] == Binding.reference("src")  # {src}: a remap
    assert params["c"] == Binding.reference("dst")  # an output too
    assert params["d"] == Binding.fixed(1, ParamType.ANY)  # given: an integer, not "1"
    assert "a" not in params  # the subtree's default, 5
    sub = spec.subtrees[0]
    assert [(p.name, p.default) for p in sub.inputs if p.name in "ab"] == [("a", 5), ("b", None)]
    # BehaviorTree.CPP 4.10 ran it to dst = 16 (tests/engine/data/btcpp/builtins)
    assert _run(registry, spec) == {"src": 10, "dst": 16}


def test_the_export_loads_back_to_the_same_run(registry: CapabilityRegistry) -> None:
    written = export_xml(import_xml(DEFAULTS, "defaults.xml"), {})
    assert 'd="1"' in written and 'default="5"' in written  # not json:1, as BehaviorTree.CPP
    again = import_xml(written, "again.xml")
    assert _run(registry, again) == {"src": 10, "dst": 16}


def test_a_default_of_own_name_is_refused() -> None:
    """BehaviorTree.CPP would remap the port to an entry called "=" (only an instance's
    ``{=}`` means the port's own name).
    """
    text = _file(
        '<input_port name="a" default="{=}"/>', '<Script code="r := a"/>', '<SubTree ID="Inner"/>'
    )
    with pytest.raises(XmlFileError, match=r"\{=\} \(an entry called '='\)"):
        import_xml(text, "own.xml")
    given = text.replace('<SubTree ID="Inner"/>', '<SubTree ID="Inner" a="{=}"/>')
    assert _instance(import_xml(given, "given.xml"))["a"] == Binding.reference("a")


def test_a_port_without_a_default_must_be_remapped() -> None:
    text = _file('<input_port name="a"/>', '<Script code="r := a"/>', '<SubTree ID="Inner"/>')
    with pytest.raises(XmlFileError) as caught:
        import_xml(text, "mandatory.xml")
    assert 'SubTree ID="Inner"' in str(caught.value)
    assert "a mandatory port called [a] that is not remapped" in str(caught.value)
    given = text.replace('<SubTree ID="Inner"/>', '<SubTree ID="Inner" a="3"/>')
    assert _instance(import_xml(given, "given.xml"))["a"] == Binding.fixed(3, ParamType.ANY)


@pytest.mark.parametrize(
    ("text", "value"),
    [("3", 3), ("-3", -3), ("2.5", 2.5), ("1e3", 1000.0), ("a;b", "a;b"), ("x1", "x1")],
)
def test_an_untyped_constant_is_stored_as_btcpp_stores_it(text: str, value: object) -> None:
    xml = _file(
        '<input_port name="a"/>', '<Script code="r := a"/>', f'<SubTree ID="Inner" a="{text}"/>'
    )
    bound = _instance(import_xml(xml, "c.xml"))["a"]
    assert bound.value == value and type(bound.value) is type(value)


def test_a_typed_model_port_keeps_its_type() -> None:
    xml = _file(
        '<input_port name="a" type="std::string" default="5"/>',
        '<Script code="r := a"/>',
        '<SubTree ID="Inner"/>',
    )
    sub = import_xml(xml, "typed.xml").subtrees[0]
    assert [(p.name, p.type, p.default) for p in sub.inputs] == [("a", ParamType.TEXT, "5")]
