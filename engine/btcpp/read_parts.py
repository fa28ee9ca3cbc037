"""What BehaviorTree.CPP XML import reads besides the nodes: the TreeNodesModel, the plan's
own data (``<CostarPlan>``) and subtree definitions; and the problem list every part adds to.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from engine.btcpp.errors import XmlProblem
from engine.btcpp.imported import XmlLines
from engine.btcpp.names import decode_port
from engine.btcpp.values import param_type_of_model, parse_value
from engine.btcpp.xmltree import Element
from engine.spec import (
    NodeKind,
    NodeLayout,
    NodeSpec,
    ParameterDecl,
    PlanSpec,
    RunPolicy,
    SubtreePort,
    SubtreeSpec,
)
from engine.tree import DEFAULT_GIVE_UP_AFTER
from engine.types import ParamType, Waypoint

__all__ = ["Model", "ReaderBase", "read_models"]


@dataclass
class Model:
    """A node model of the TreeNodesModel: its element (Action, Condition, SubTree...) and
    port name -> (input_port/output_port/inout_port, our type, default text, doc).
    """

    element: str
    ports: dict[str, tuple[str, ParamType, str | None, str]] = field(default_factory=dict)


def read_models(
    element: Element | None, problem: Callable[[int, str, str], None] | None = None
) -> dict[str, Model]:
    """The models of a ``<TreeNodesModel>`` by id (none when the file has none).

    Args:
        element: the TreeNodesModel.
        problem: told (line, expected, got) of a model whose ID an earlier one has.
    """
    models: dict[str, Model] = {}
    for item in element.children if element is not None else []:
        model_id = item.attrs.get("ID", "")
        if model_id in models and problem is not None:
            problem(item.line, "a model ID no other model has", repr(model_id))
        model = models.setdefault(model_id, Model(item.tag))
        for port in item.children:
            doc = port.attrs.get("description") or port.text.strip()
            ptype = param_type_of_model(port.attrs.get("type"))
            entry = (port.tag, ptype, port.attrs.get("default"), doc)
            try:
                model.ports[decode_port(port.attrs.get("name", ""))] = entry
            except ValueError:
                continue  # not one of ours: its nodes are reported where they are used
    return models


class ReaderBase:
    """Collects problems (every one, with its line) while parts of a file are read."""

    def __init__(self) -> None:
        self.problems: list[XmlProblem] = []
        self.models: dict[str, Model] = {}
        self.lines = XmlLines()  # where the plan's parts are, for later problems

    def problem(self, line: int, expected: str, got: str) -> None:
        self.problems.append(XmlProblem(line, expected, got))

    # ---- the plan's own data and subtree definitions

    def _plan_data(self, data: Element, plan: PlanSpec) -> None:
        attrs = data.attrs
        plan.id = attrs.get("id") or plan.id
        plan.name = attrs.get("name", plan.name)
        plan.description = attrs.get("description", "")
        policies = [p.value for p in RunPolicy]
        if attrs.get("run_policy", "once") in policies:
            plan.run_policy = RunPolicy(attrs.get("run_policy", "once"))
        else:
            self.problem(
                data.line, f"run_policy one of {', '.join(policies)}", repr(attrs["run_policy"])
            )
        give_up = attrs.get("give_up_after", str(DEFAULT_GIVE_UP_AFTER))
        if give_up.isdigit():
            plan.give_up_after = int(give_up)
        else:
            self.problem(data.line, "give_up_after a whole number of 0 or more", repr(give_up))
        plan.reset_cell = attrs.get("reset_cell") == "true"
        plan.scene = attrs.get("scene", "")
        for item in data.children:
            if item.tag == "Parameter":
                self.lines.parameters[item.attrs.get("name", "")] = item.line
                ptype = self._ptype(item, item.attrs.get("type", ""))
                raw = item.attrs.get("value")
                value = None if raw is None else self._value(item, ptype, raw, "value")
                plan.parameters.append(
                    ParameterDecl(
                        item.attrs.get("name", ""), ptype, value, item.attrs.get("doc", "")
                    )
                )
            elif item.tag == "Waypoint":
                waypoint = self._value(
                    item, ParamType.WAYPOINT, item.attrs.get("value", ""), "value"
                )
                if isinstance(waypoint, Waypoint):
                    plan.waypoints.append(waypoint)
            elif item.tag == "Object":
                plan.objects.append(item.attrs.get("name", ""))
            elif item.tag == "Layout":
                plan.layout[item.attrs.get("_uid", "")] = self._layout(item) or NodeLayout()

    def _ptype(self, element: Element, name: str) -> ParamType:
        try:
            return ParamType(name)
        except ValueError:
            self.problem(
                element.line, f"a type ({', '.join(t.value for t in ParamType)})", repr(name)
            )
            return ParamType.ANY

    def _value(self, element: Element, ptype: ParamType, text: str, what: str) -> object:
        try:
            return parse_value(ptype, text)
        except ValueError as exc:
            self.problem(element.line, f"{what}: {exc}", f"<{element.tag}>")
            return None

    def _subtree(self, tree_id: str, element: Element) -> SubtreeSpec:
        attrs = element.attrs
        sub = SubtreeSpec(
            id=attrs.get("_uid", tree_id),
            name=attrs.get("_name", tree_id),
            tree=NodeSpec(NodeKind.SEQUENCE),
            date=attrs.get("_date", ""),
            description=attrs.get("_description", ""),
        )
        try:
            sub.version = int(attrs.get("_version", "1"))
            shared = json.loads(attrs.get("_shared", "[]"))
            if not isinstance(shared, list) or not all(isinstance(s, str) for s in shared):
                raise ValueError
            sub.shared_names = shared
        except ValueError:
            self.problem(
                element.line, "_version a whole number, _shared a JSON list of names", "other"
            )
        model = self.models.get(tree_id)
        for name, (direction, ptype, default, doc) in (model.ports if model else {}).items():
            value = (
                None
                if default is None
                else self._value(element, ptype, default, f"default of {name}")
            )
            port = SubtreePort(name, ptype, doc, value if direction != "output_port" else None)
            (sub.outputs if direction == "output_port" else sub.inputs).append(port)
        return sub

    # ---- nodes

    def _layout(self, element: Element) -> NodeLayout | None:
        if "_x" not in element.attrs and "_y" not in element.attrs:
            return None
        try:
            x, y = float(element.attrs.get("_x", "0")), float(element.attrs.get("_y", "0"))
            if not (math.isfinite(x) and math.isfinite(y)):
                raise ValueError
        except ValueError:
            self.problem(
                element.line,
                "_x and _y numbers",
                f"{element.attrs.get('_x')!r}, {element.attrs.get('_y')!r}",
            )
            return None
        return NodeLayout(x, y, element.attrs.get("_collapsed") == "true")
