"""What BehaviorTree.CPP XML import reads besides the nodes: the TreeNodesModel, the plan's
own data (``<CostarPlan>``) and subtree definitions; and the problem list every part adds to.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

from engine.btcpp.errors import XmlProblem
from engine.btcpp.imported import XmlLines
from engine.btcpp.names import decode_port
from engine.btcpp.values import param_type_of_model, parse_value, untyped_constant
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

__all__ = ["Model", "ReaderBase", "model_remaps", "read_models"]


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
            if item.tag == "SubTree" and "type" not in port.attrs:
                ptype = ParamType.ANY  # BehaviorTree.CPP's SubTree ports take any type

            entry = (port.tag, ptype, port.attrs.get("default"), doc)
            try:
                model.ports[decode_port(port.attrs.get("name", ""))] = entry
            except ValueError:
                continue  # not one of ours: its nodes are reported where they are used
    return models


# A SubTree instance, or the BehaviorTree of a subtree (the defaults of its model's ports).
_SUBTREE_TAGS = ("SubTree", "BehaviorTree")


def _is_pointer(text: str) -> bool:
    """``{key}`` (BehaviorTree.CPP's isBlackboardPointer)."""
    stripped = text.strip()
    return len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}"


def model_remaps(
    tree_id: str, model: Model, given: Iterable[str], problem: Callable[[str, str], None]
) -> dict[str, str]:
    """What a ``<SubTree>`` instance that leaves out ports of its TreeNodesModel gets, as
    BehaviorTree.CPP's XML parser gives it: port -> the key its ``{key}`` default remaps it
    to. A default of another value is the subtree port's default (an input's); a port left
    out with no default is refused, with BehaviorTree.CPP's reason, told to
    ``problem(expected, got)``, and so is a default of ``{=}`` (BehaviorTree.CPP reads
    ``{=}`` as the port's own name only in an instance; as a default it remaps the port to an
    entry called ``=``, which nothing can write).
    """
    remaps: dict[str, str] = {}
    for name, (_direction, _ptype, default, _doc) in model.ports.items():
        if name in given:
            continue
        if default is None:
            problem(
                f'a remapping of every port of the <TreeNodesModel>\'s <SubTree ID="{tree_id}"> '
                "without a default",
                f"a mandatory port called [{name}] that is not remapped",
            )
        elif _is_pointer(default):
            key = default.strip()[1:-1].strip()
            if key == "=":
                problem(
                    f'a default of port [{name}] of <SubTree ID="{tree_id}"> other than {{=}}',
                    "{=} (an entry called '=')",
                )
            else:
                remaps[name] = key
    return remaps


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
        if ptype is ParamType.ANY and element.tag in _SUBTREE_TAGS and not text.startswith("json:"):
            return untyped_constant(text)
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
                if default is None or _is_pointer(default)  # {key}: a remap of the instance
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
