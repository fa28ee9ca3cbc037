"""Writing a plan as BehaviorTree.CPP v4 XML (the format is described in engine.btcpp)."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from engine.btcpp.errors import XmlExportError
from engine.btcpp.logic import BUILTIN_MODELS, LOGIC, LOGIC_BY_MODEL, model_of
from engine.btcpp.names import encode_id, encode_port, readable_tree_id
from engine.btcpp.values import MODEL_TYPE, untyped_text, value_text
from engine.conditions import Condition
from engine.kinds import KIND_PORTS
from engine.operations import Direction, OperationKind, OperationManifest
from engine.spec import Binding, NodeKind, NodeLayout, NodeSpec, PlanSpec, SubtreeSpec
from engine.tree import DEFAULT_GIVE_UP_AFTER
from engine.types import ParamType, check_value, type_of_value

__all__ = ["FORMAT_VERSION", "UNUSED_OUTPUT", "export_xml"]

_ILLEGAL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
FORMAT_VERSION = 1  # of the CostarPlan element: what BehaviorTree.CPP does not hold
# An output an instance does not copy out: BehaviorTree.CPP needs every declared port of a
# SubTree remapped, so it goes to this private (``_``) entry, which nothing reads.
UNUSED_OUTPUT = "{_}"


@dataclass
class _Port:
    direction: str  # input_port, output_port, inout_port
    ptype: ParamType
    default: str | None = None
    doc: str = ""


@dataclass
class _Model:
    element: str  # Action, Condition, Decorator, SubTree
    ports: dict[str, _Port] = field(default_factory=dict)


def _port_of_spec(
    direction: Direction,
    ptype: ParamType,
    default: Any,
    doc: str,
    types: tuple[ParamType, ...] = (),
) -> _Port:
    tag = "output_port" if direction is Direction.OUT else "input_port"
    text = None
    if default is not None:
        # A default may be of another of the port's types (an empty Text for a Pose port).
        fits = [t for t in (ptype, *types) if check_value(t, default)]
        text = value_text(fits[0] if fits else type_of_value(default), default)
    return _Port(tag, ptype, text, doc)


def _operation_model(manifest: OperationManifest) -> _Model:
    element = "Condition" if manifest.kind is OperationKind.CONDITION else "Action"
    ports = {
        p.name: _port_of_spec(p.direction, p.type, p.default, p.doc, p.types)
        for p in manifest.ports
    }
    return _Model(element, ports)


def _floats(value: float) -> str:
    return repr(float(value))


class _Writer:
    def __init__(self, plan: PlanSpec, manifests: Mapping[str, OperationManifest]) -> None:
        self.plan = plan
        self.manifests = manifests
        self.models: dict[str, _Model] = {}
        # A tree may not take the id of a node model (BehaviorTree.CPP refuses the file).
        self.taken: set[str] = set(BUILTIN_MODELS) | set(LOGIC_BY_MODEL)
        self.tree_ids: dict[tuple[str, int], str] = {}

    def fail(self, where: str, expected: str, got: str) -> XmlExportError:
        return XmlExportError(self.plan.name or "<plan>", where, expected, got)

    # ---- the document

    def document(self) -> ET.Element:
        plan = self.plan
        if plan.tree is None:
            raise self.fail("the plan", "a tree to export", "an empty plan")
        for _, node in self._all_nodes():
            if node.kind is NodeKind.OPERATION and node.op is not None:
                self.taken.add(self._op_model_id(node.op))
        main_id = readable_tree_id(plan.name or "Plan", self.taken)
        for sub in plan.subtrees:
            self.tree_ids[(sub.id, sub.version)] = readable_tree_id(sub.name, self.taken)
        root = ET.Element("root", {"BTCPP_format": "4", "main_tree_to_execute": main_id})
        root.append(self._plan_data(main_id))
        main = ET.SubElement(root, "BehaviorTree", {"ID": main_id})
        main.append(self._node(plan.tree, plan.layout, plan.tree.label))
        _unique_subtree_names(main)
        for sub in plan.subtrees:
            root.append(self._subtree_tree(sub))
        root.append(self._models())
        return root

    def _all_nodes(self) -> list[tuple[str, NodeSpec]]:
        found = list(self.plan.walk())
        for sub in self.plan.subtrees:
            found += list(sub.tree.walk(f"{sub.name}:{sub.tree.label}"))
        return found

    def _op_model_id(self, op: str) -> str:
        return encode_id(op, avoid=BUILTIN_MODELS)

    def _plan_data(self, main_id: str) -> ET.Element:
        plan = self.plan
        data = ET.Element(
            "CostarPlan",
            {
                "format_version": str(FORMAT_VERSION),
                "tree": main_id,
                "id": plan.id,
                "name": plan.name,
                "description": plan.description,
                "run_policy": plan.run_policy.value,
                "reset_cell": "true" if plan.reset_cell else "false",
                "scene": plan.scene,
            },
        )
        if plan.give_up_after != DEFAULT_GIVE_UP_AFTER:
            data.set("give_up_after", str(plan.give_up_after))
        for decl in plan.parameters:
            attrs = {"name": decl.name, "type": ParamType(decl.type).value}
            if decl.value is not None:
                attrs["value"] = self._text(decl.type, decl.value, f"parameter {decl.name}")
            if decl.doc:
                attrs["doc"] = decl.doc
            ET.SubElement(data, "Parameter", attrs)
        for waypoint in plan.waypoints:
            ET.SubElement(
                data,
                "Waypoint",
                {"value": self._text(ParamType.WAYPOINT, waypoint, f"waypoint {waypoint.name}")},
            )
        for name in plan.objects:
            ET.SubElement(data, "Object", {"name": name})
        in_tree = {node.id for _, node in plan.walk()}
        for node_id, layout in plan.layout.items():
            if node_id not in in_tree:  # the file keeps it; so does the XML
                ET.SubElement(data, "Layout", {"_uid": node_id, **self._layout_attrs(layout)})
        return data

    def _subtree_tree(self, sub: SubtreeSpec) -> ET.Element:
        element = ET.Element(
            "BehaviorTree",
            {
                "ID": self.tree_ids[(sub.id, sub.version)],
                "_uid": sub.id,
                "_name": sub.name,
                "_version": str(sub.version),
                "_date": sub.date,
                "_description": sub.description,
                "_shared": json.dumps(sub.shared_names, ensure_ascii=False),
            },
        )
        element.append(self._node(sub.tree, sub.layout, f"{sub.name}:{sub.tree.label}"))
        _unique_subtree_names(element)
        ports = {p.name: _port_of_spec(Direction.IN, p.type, p.default, p.doc) for p in sub.inputs}
        for port in sub.inputs:  # an untyped default as BehaviorTree.CPP reads it: 5, not json:5
            if port.type is ParamType.ANY and (text := untyped_text(port.default)) is not None:
                ports[port.name].default = text
        for port in sub.outputs:
            ports[port.name] = _port_of_spec(Direction.OUT, port.type, None, port.doc)
        self.models[self.tree_ids[(sub.id, sub.version)]] = _Model("SubTree", ports)
        return element

    # ---- nodes

    def _node(self, node: NodeSpec, layout: Mapping[str, NodeLayout], path: str) -> ET.Element:
        attrs: dict[str, str] = {}
        if node.kind is NodeKind.OPERATION:
            tag = self._operation(node, attrs, path)
        elif node.kind is NodeKind.SUBTREE:
            tag = self._instance(node, attrs, path)
        else:
            tag = self._logic(node, attrs, path)
        element = ET.Element(tag)
        if tag == "SubTree":
            element.set("ID", attrs.pop("ID"))
        if node.name:
            element.set("name", node.name)
        for key, value in attrs.items():
            element.set(key, value)
        given = {Condition(c): text for c, text in node.conditions.items()}
        for condition in Condition:  # BehaviorTree.CPP's own attributes: it runs them
            text = given.get(condition, "")
            if text.strip():
                element.set(condition.attribute, text)
        element.set("_uid", node.id)
        if node.id in layout:
            for key, value in self._layout_attrs(layout[node.id]).items():
                element.set(key, value)
        for index, child in enumerate(node.children):
            element.append(self._node(child, layout, f"{path}/{child.label}[{index}]"))
        return element

    def _layout_attrs(self, layout: NodeLayout) -> dict[str, str]:
        attrs = {"_x": _floats(layout.x), "_y": _floats(layout.y)}
        if layout.collapsed:
            attrs["_collapsed"] = "true"
        return attrs

    def _bindings(self, node: NodeSpec, model: _Model, attrs: dict[str, str], path: str) -> None:
        """Ports as attributes; ``_types`` names the type of a fixed value whose type is
        not the port's declared one (a port that takes several types).
        """
        other_types: list[str] = []
        for port, binding in sorted(node.params.items()):
            if binding.ref is None and binding.type is None and binding.value is None:
                continue
            attr = encode_port(port)
            declared = model.ports.get(port)
            if binding.ref is not None:
                attrs[attr] = "{" + binding.ref + "}"
                if declared is None:
                    model.ports[port] = _Port("inout_port", ParamType.ANY)
                continue
            ptype = ParamType(binding.type) if binding.type is not None else ParamType.ANY
            if declared is None:
                declared = model.ports[port] = _Port("input_port", ptype)
            attrs[attr] = self._value(binding, ptype, path, port)
            if ptype is not declared.ptype:
                other_types.append(f"{port}={ptype.value}")
        if other_types:
            attrs["_types"] = ";".join(other_types)

    def _value(self, binding: Binding, ptype: ParamType, path: str, port: str) -> str:
        return self._text(ptype, binding.value, f"{path} [{port}]")

    def _text(self, ptype: ParamType, value: Any, where: str) -> str:
        try:
            return value_text(ptype, value)
        except ValueError as exc:
            raise self.fail(where, "finite numbers", repr(value)[:80]) from exc

    def _operation(self, node: NodeSpec, attrs: dict[str, str], path: str) -> str:
        if node.op is None:
            raise self.fail(path, "an operation id", "none")
        model_id = self._op_model_id(node.op)
        if model_id not in self.models:
            manifest = self.manifests.get(node.op)
            self.models[model_id] = (
                _operation_model(manifest) if manifest is not None else _Model("Action")
            )
        self._bindings(node, self.models[model_id], attrs, path)
        return model_id

    def _instance(self, node: NodeSpec, attrs: dict[str, str], path: str) -> str:
        ref = node.subtree
        sub = self.plan.subtree(ref) if ref is not None else None
        if ref is None or sub is None:
            raise self.fail(path, "the definition of the subtree the instance runs", "none")
        attrs["ID"] = tree_id = self.tree_ids[(ref.id, ref.version)]
        if tree_id not in self.models:
            self._subtree_tree(sub)  # declares its model
        self._bindings(node, self.models[tree_id], attrs, path)
        for name, binding in node.params.items():  # untyped constants: 5, not json:5
            declared = self.models[tree_id].ports.get(name)
            if binding.ref is None and declared is not None and declared.ptype is ParamType.ANY:
                text = untyped_text(binding.value)
                if text is not None and binding.type in (None, ParamType.ANY):
                    attrs[encode_port(name)] = text
        for port in sub.outputs:  # BehaviorTree.CPP wants every port remapped: a sink
            attrs.setdefault(encode_port(port.name), UNUSED_OUTPUT)
        for name in sub.shared_names:  # crosses the scope on purpose: remapped to itself
            attrs.setdefault(name, "{" + name + "}")
        return "SubTree"

    def _logic(self, node: NodeSpec, attrs: dict[str, str], path: str) -> str:
        logic = LOGIC[node.kind]
        for name, binding in sorted(node.params.items()):
            if name in logic.implied:
                continue  # the model's id says it (LoopInt: type int)
            mapping = logic.settings.get(name)
            if mapping is None:
                raise self.fail(path, f"settings of {node.kind.value}", repr(name))
            if binding.ref is not None:
                attrs[mapping.port] = "{" + binding.ref + "}"
                continue
            if binding.value is None:
                continue
            value = binding.value
            text = mapping.write(value)
            attrs[mapping.port] = text
            exact = value if isinstance(value, str) else float(value)
            try:
                same = mapping.read(text) == exact
            except ValueError:
                same = False
            if not same:
                attrs[f"_{name}"] = value if isinstance(value, str) else repr(exact)
        if not logic.builtin and logic.model not in self.models:
            self.models[logic.model] = self._logic_model(node.kind)
        return model_of(node)

    def _logic_model(self, kind: NodeKind) -> _Model:

        ports = {
            p.name: _port_of_spec(Direction.IN, p.type, p.default, p.doc) for p in KIND_PORTS[kind]
        }
        return _Model(LOGIC[kind].element, ports)

    # ---- the model

    def _models(self) -> ET.Element:
        models = ET.Element("TreeNodesModel")
        for model_id in sorted(self.models):
            model = self.models[model_id]
            element = ET.SubElement(models, model.element, {"ID": model_id})
            for name, port in model.ports.items():
                attrs = {"name": encode_port(name), "type": MODEL_TYPE[port.ptype]}
                if port.default is not None:
                    attrs["default"] = port.default
                if model.element == "SubTree" and port.doc:
                    attrs["description"] = port.doc  # what BehaviorTree.CPP reads there
                port_element = ET.SubElement(element, port.direction, attrs)
                if port.doc:
                    port_element.text = port.doc
        return models


def _check_characters(root: ET.Element, plan: str) -> None:
    """XML 1.0 cannot hold most control characters, not even escaped: refuse them by name."""
    for element in root.iter():
        for key, value in element.attrib.items():
            bad = next((c for c in value if _ILLEGAL.match(c)), None)
            if bad is not None:
                where = element.get("name") or element.get("_uid") or element.tag
                raise XmlExportError(
                    plan, f"{where} [{key}]", "text without control characters", repr(bad)
                )


def export_xml(plan: PlanSpec, manifests: Mapping[str, OperationManifest]) -> str:
    """The BehaviorTree.CPP v4 XML of a plan (see :mod:`engine.btcpp`).

    Args:
        plan: the plan; its embedded subtrees become BehaviorTrees of their own.
        manifests: operation id -> manifest, for the typed ports of the TreeNodesModel
            (an operation missing here is declared with the ports its nodes bind).

    Raises:
        XmlExportError: the plan has no tree, a port name BehaviorTree.CPP cannot hold, a
            value that is not finite, or an instance without its subtree's definition.
    """
    root = _Writer(plan, manifests).document()
    _check_characters(root, plan.name or "<plan>")
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + body + "\n"


def _unique_subtree_names(tree: ET.Element) -> None:
    """Give the SubTree instances of one BehaviorTree distinct ``name`` attributes.

    BehaviorTree.CPP 4.10 refuses two SubTree nodes of one tree with the same name (it builds
    each instance's path from the names of the SubTree nodes above it, not of other nodes);
    the later ones are written as "NAME (2)", ... and keep their own name in ``_name``, which
    the reader prefers.
    """
    taken: set[str] = set()
    for child in tree.iter("SubTree"):
        name = child.get("name")
        if child.tag != "SubTree" or name is None:
            continue
        unique, count = name, 1
        while unique in taken:
            count += 1
            unique = f"{name} ({count})"
        if unique != name:
            child.set("name", unique)
            child.set("_name", name)
        taken.add(unique)
