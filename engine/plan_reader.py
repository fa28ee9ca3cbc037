"""Reading plan files: every shape checked, errors name the file, JSON path and expectation."""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any, NoReturn

from engine.conditions import Condition
from engine.json_reader import JsonFileError, JsonReader, parse_json, read_json_file
from engine.kinds import setting as kind_setting
from engine.plan_format import (
    FORMAT,
    FORMAT_VERSION,
    KIND_ALIASES,
    MAX_NESTING,
    MAX_TREE_DEPTH,
    NODE_FIELDS,
    NODE_FIELDS_V1,
    READABLE_VERSIONS,
    SUBTREE_FIELDS,
    TOP_FIELDS,
    PlanFileError,
    at,
    describe,
)
from engine.spec import (
    KIND_CATEGORY,
    Binding,
    Category,
    NodeKind,
    NodeLayout,
    NodeSpec,
    ParameterDecl,
    PlanSpec,
    RunPolicy,
    SubtreePort,
    SubtreeRef,
    SubtreeSpec,
    new_id,
)
from engine.tree import DEFAULT_GIVE_UP_AFTER
from engine.types import ParamType, Waypoint, with_article

__all__ = ["load_plan", "loads_plan", "read_subtree"]

V1_WAIT_OP = "timing.wait"  # format 1's operation for what is the Wait node


class _Reader:
    """Turns a parsed document into a PlanSpec, failing at the first thing that is off."""

    def __init__(self, file: str, aliases: Mapping[str, str]) -> None:
        self.file = file
        self.aliases = aliases
        self.ids: dict[str, str] = {}  # node id -> JSON path of the node that has it
        self.version: object = FORMAT_VERSION  # of the file, known after check_format

    def fail(self, path: str, expected: str, got: str) -> NoReturn:
        raise PlanFileError(self.file, path, expected, got)

    def at(self, value: Any, path: str) -> JsonReader:
        """The one JSON reader, at ``value`` (found at ``path``) of this file."""
        return JsonReader(value, self.file, path, PlanFileError)

    def fields(
        self, value: Any, path: str, fields: tuple[str, ...], required: tuple[str, ...] = ()
    ) -> dict[str, Any]:
        return self.at(value, path).as_object(fields, required)

    def mapping(self, value: Any, path: str, what: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            self.fail(path, f"an object of {what}", describe(value))
        return value

    def text(self, value: Any, path: str, nonempty: bool = False) -> str:
        return self.at(value, path).as_text(nonempty)

    def flag(self, value: Any, path: str) -> bool:
        return self.at(value, path).as_bool()

    def items(self, value: Any, path: str, what: str) -> list[Any]:
        return self.at(value, path).as_list(what)

    def unique(self, name: str, before: list[str], path: str) -> None:
        if name in before:
            self.fail(path, "a name not used before in this list", f"{name!r} a second time")

    def choice(self, value: Any, path: str, choices: list[str]) -> str:
        if value not in choices:
            self.fail(path, f"one of {', '.join(choices)}", describe(value))
        return str(value)

    def value(self, ptype: ParamType, value: Any, path: str) -> Any:
        return self.at(value, path).as_typed(ptype)

    def ptype(self, value: Any, path: str) -> ParamType:
        return ParamType(self.choice(value, path, [t.value for t in ParamType]))

    # ---- the document

    def plan(self, doc: Any) -> PlanSpec:
        doc = self.fields(doc, "$", TOP_FIELDS, required=("format", "format_version"))
        plan = PlanSpec(
            id=self.text(doc.get("id", new_id()), "$.id", nonempty=True),
            name=self.text(doc.get("name", ""), "$.name"),
            description=self.text(doc.get("description", ""), "$.description"),
            run_policy=RunPolicy(
                self.choice(
                    doc.get("run_policy", "once"), "$.run_policy", [p.value for p in RunPolicy]
                )
            ),
            give_up_after=self.at(doc, "$").integer("give_up_after", DEFAULT_GIVE_UP_AFTER, lo=0),
            reset_cell=self.flag(doc.get("reset_cell", False), "$.reset_cell"),
            scene=self.text(doc.get("scene", ""), "$.scene"),
        )
        if doc.get("tree") is not None:
            plan.tree = self.node(doc["tree"], "$.tree", 1)
        plan.parameters = self.parameters(doc.get("parameters", []), "$.parameters")
        plan.waypoints = self.waypoints(doc.get("waypoints", []), "$.waypoints")
        plan.objects = self.objects(doc.get("objects", []), "$.objects")
        plan.layout = self.layout(doc.get("layout", {"nodes": {}}), "$.layout")
        for index, item in enumerate(self.items(doc.get("subtrees", []), "$.subtrees", "subtrees")):
            here = at("$.subtrees", index)
            subtree = self.subtree(item, here, SUBTREE_FIELDS)
            if plan.subtree(subtree.ref) is not None:
                self.fail(here, "each subtree version once", f"{subtree.name!r} a second time")
            plan.subtrees.append(subtree)
        return plan

    def subtree(self, value: Any, path: str, fields: tuple[str, ...]) -> SubtreeSpec:
        """A subtree definition; its node ids are a namespace of their own (as in a file)."""
        obj = self.fields(value, path, fields, ("id", "name", "version", "tree"))
        outer_ids, self.ids = self.ids, {}
        try:
            tree = self.node(obj["tree"], at(path, "tree"), 1)
        finally:
            self.ids = outer_ids
        inputs = self.ports(obj.get("inputs", []), at(path, "inputs"), with_default=True)
        outputs = self.ports(obj.get("outputs", []), at(path, "outputs"), with_default=False)
        shared: list[str] = []
        for index, name in enumerate(
            self.items(obj.get("shared_names", []), at(path, "shared_names"), "names")
        ):
            self.unique(name, shared, at(at(path, "shared_names"), index))
            shared.append(self.text(name, at(at(path, "shared_names"), index), nonempty=True))
        return SubtreeSpec(
            id=self.text(obj["id"], at(path, "id"), nonempty=True),
            name=self.text(obj["name"], at(path, "name"), nonempty=True),
            tree=tree,
            version=self.at(obj["version"], at(path, "version")).as_integer(lo=1),
            date=self.text(obj.get("date", ""), at(path, "date")),
            description=self.text(obj.get("description", ""), at(path, "description")),
            inputs=inputs,
            outputs=outputs,
            shared_names=shared,
            layout=self.layout(obj.get("layout", {"nodes": {}}), at(path, "layout")),
        )

    def ports(self, value: Any, path: str, with_default: bool) -> list[SubtreePort]:
        ports: list[SubtreePort] = []
        fields = ("name", "type", "doc", "default") if with_default else ("name", "type", "doc")
        for index, item in enumerate(self.items(value, path, "ports")):
            here = at(path, index)
            obj = self.fields(item, here, fields, ("name", "type"))
            name = self.text(obj["name"], at(here, "name"), nonempty=True)
            self.unique(name, [p.name for p in ports], at(here, "name"))
            ptype = self.ptype(obj["type"], at(here, "type"))
            raw = obj.get("default")
            default = None if raw is None else self.value(ptype, raw, at(here, "default"))
            doc = self.text(obj.get("doc", ""), at(here, "doc"))
            ports.append(SubtreePort(name, ptype, doc, default))
        return ports

    def subtree_ref(self, value: Any, path: str) -> SubtreeRef:
        obj = self.fields(value, path, ("id", "version"), ("id", "version"))
        return SubtreeRef(
            self.text(obj["id"], at(path, "id"), nonempty=True),
            self.at(obj["version"], at(path, "version")).as_integer(lo=1),
        )

    def node(self, value: Any, path: str, depth: int) -> NodeSpec:
        if depth > MAX_TREE_DEPTH:
            self.fail(path, f"a tree at most {MAX_TREE_DEPTH} levels deep", "a deeper tree")
        names = NODE_FIELDS_V1 if self.version == 1 else NODE_FIELDS
        obj = self.fields(value, path, names, required=("id", "kind"))
        node_id = self.text(obj["id"], at(path, "id"), nonempty=True)
        if node_id in self.ids:
            self.fail(
                at(path, "id"),
                "an id no other node has",
                f"{node_id!r}, already the id of {self.ids[node_id]}",
            )
        self.ids[node_id] = path
        kind = self.kind(obj["kind"], at(path, "kind"))
        node = NodeSpec(kind, name=self.text(obj.get("name", ""), at(path, "name")), id=node_id)
        if kind is NodeKind.OPERATION:
            node.op = self.operation_id(obj.get("op"), at(path, "op"))
        elif "op" in obj:
            self.fail(
                at(path, "op"),
                "no op: only operation nodes have one",
                f"{with_article(kind.value)} node",
            )
        if kind is NodeKind.SUBTREE:
            if "subtree" not in obj:
                self.fail(
                    at(path, "subtree"),
                    'the subtree it runs {"id": ..., "version": ...}',
                    "nothing",
                )
            node.subtree = self.subtree_ref(obj["subtree"], at(path, "subtree"))
        elif "subtree" in obj:
            self.fail(
                at(path, "subtree"),
                "no subtree: only subtree instances have one",
                f"{with_article(kind.value)} node",
            )
        params = self.mapping(obj.get("params", {}), at(path, "params"), "port -> binding")
        node.params = {
            port: self.binding(b, at(at(path, "params"), port)) for port, b in params.items()
        }
        if self.version == 1:
            self.v1_settings(node, obj.get("config", {}), at(path, "config"))
        node.conditions = self.conditions(obj.get("conditions", {}), at(path, "conditions"))
        children = self.items(obj.get("children", []), at(path, "children"), "nodes")
        self.check_children(kind, len(children), at(path, "children"))
        for index, child in enumerate(children):
            node.children.append(self.node(child, at(at(path, "children"), index), depth + 1))
        return node

    def conditions(self, value: Any, path: str) -> dict[Condition, str]:
        """A node's pre- and post-conditions: condition -> script (parsed when validated)."""
        given = self.mapping(value, path, "condition -> script")
        out: dict[Condition, str] = {}
        for key, text in given.items():
            here = at(path, key)
            condition = Condition(self.choice(key, here, [c.value for c in Condition]))
            script = self.text(text, here)
            if script.strip():
                out[condition] = script
        return out

    def kind(self, value: Any, path: str) -> NodeKind:
        if isinstance(value, str) and value in KIND_ALIASES:
            value = KIND_ALIASES[value]
        return NodeKind(self.choice(value, path, [k.value for k in NodeKind]))

    def operation_id(self, value: Any, path: str) -> str:
        if value is None:
            self.fail(path, "an operation id such as 'motion.move_to'", "nothing")
        op = self.text(value, path, nonempty=True)
        seen = {op}
        while op in self.aliases and self.aliases[op] not in seen:  # follow renames, no cycles
            op = self.aliases[op]
            seen.add(op)
        return op

    def check_children(self, kind: NodeKind, count: int, path: str) -> None:
        category = KIND_CATEGORY[kind]
        if category is Category.LEAF and count:
            self.fail(path, f"no children: a {kind.value} node is a leaf", f"{count} children")
        if category is Category.DECORATOR and count > 1:
            self.fail(path, f"at most one child under a {kind.value} node", f"{count} children")

    def binding(self, value: Any, path: str) -> Binding:
        obj = self.fields(value, path, ("type", "value", "ref"))
        if "ref" in obj:
            if "type" in obj or "value" in obj:
                self.fail(
                    path, "a fixed value (type, value) or a reference (ref), not both", "both"
                )
            return Binding.reference(self.text(obj["ref"], at(path, "ref"), nonempty=True))
        if "type" not in obj or "value" not in obj:
            self.fail(
                path,
                'a fixed value {"type": ..., "value": ...} or a reference {"ref": ...}',
                describe(obj),
            )
        ptype = self.ptype(obj["type"], at(path, "type"))
        return Binding.fixed(self.value(ptype, obj["value"], at(path, "value")), ptype)

    def v1_settings(self, node: NodeSpec, value: Any, path: str) -> None:
        """Version 1 kept logic-node settings in "config" and had the operation timing.wait."""
        if node.op == V1_WAIT_OP:
            node.kind, node.op = NodeKind.WAIT, None
        for key, setting in self.mapping(value, path, "setting -> value").items():
            if setting is None:
                continue
            try:
                node.params[key] = kind_setting(node.kind, key, setting)
            except ValueError:
                self.fail(at(path, key), "a number or a text", describe(setting))

    def parameters(self, value: Any, path: str) -> list[ParameterDecl]:
        decls: list[ParameterDecl] = []
        for index, item in enumerate(self.items(value, path, "parameters")):
            here = at(path, index)
            obj = self.fields(item, here, ("name", "type", "value", "doc"), ("name", "type"))
            name = self.text(obj["name"], at(here, "name"), nonempty=True)
            self.unique(name, [d.name for d in decls], at(here, "name"))
            ptype = self.ptype(obj["type"], at(here, "type"))
            raw = obj.get("value")
            initial = None if raw is None else self.value(ptype, raw, at(here, "value"))
            decls.append(
                ParameterDecl(name, ptype, initial, self.text(obj.get("doc", ""), at(here, "doc")))
            )
        return decls

    def waypoints(self, value: Any, path: str) -> list[Waypoint]:
        waypoints: list[Waypoint] = []
        for index, item in enumerate(self.items(value, path, "waypoints")):
            waypoint = self.value(ParamType.WAYPOINT, item, at(path, index))
            self.unique(waypoint.name, [w.name for w in waypoints], at(at(path, index), "name"))
            waypoints.append(waypoint)
        return waypoints

    def objects(self, value: Any, path: str) -> list[str]:
        names: list[str] = []
        for index, item in enumerate(self.items(value, path, "object names")):
            name = self.text(item, at(path, index), nonempty=True)
            self.unique(name, names, at(path, index))
            names.append(name)
        return names

    def layout(self, value: Any, path: str) -> dict[str, NodeLayout]:
        nodes = self.mapping(
            self.fields(value, path, ("nodes",)).get("nodes", {}),
            at(path, "nodes"),
            "node id -> position",
        )
        layout: dict[str, NodeLayout] = {}
        for node_id, item in nodes.items():
            here = at(at(path, "nodes"), node_id)
            obj = self.fields(item, here, ("x", "y", "collapsed"), ("x", "y"))
            x = self.value(ParamType.NUMBER, obj["x"], at(here, "x"))
            y = self.value(ParamType.NUMBER, obj["y"], at(here, "y"))
            collapsed = self.value(
                ParamType.BOOL, obj.get("collapsed", False), at(here, "collapsed")
            )
            layout[node_id] = NodeLayout(x, y, collapsed)
        return layout

    def check_format(self, doc: Any) -> None:
        """Refuse other formats and versions before anything else is looked at."""
        if not isinstance(doc, dict):
            self.fail("$", f"a {FORMAT} object", describe(doc))
        if doc.get("format") != FORMAT:
            self.fail("$.format", repr(FORMAT), describe(doc.get("format")))
        version = doc.get("format_version")
        self.version = version
        readable = ", ".join(str(v) for v in READABLE_VERSIONS)
        if isinstance(version, int) and not isinstance(version, bool) and version > FORMAT_VERSION:
            self.fail(
                "$.format_version",
                f"a format_version this program reads ({readable}); the file was written by a "
                "newer CoSTAR Instructor",
                f"format_version {version}",
            )
        if version not in READABLE_VERSIONS or isinstance(version, bool):
            self.fail(
                "$.format_version", f"one of the format versions {readable}", describe(version)
            )


def loads_plan(
    text: str, source_name: str = "<string>", aliases: Mapping[str, str] | None = None
) -> PlanSpec:
    """Read a plan from the text of a plan file.

    Args:
        text: the JSON text.
        source_name: the file as the user named it, for error messages.
        aliases: former operation ids -> current ids; the loaded spec holds current ids.

    Returns:
        The plan.

    Raises:
        PlanFileError: the text is not a plan this program reads.
    """
    doc = parse_json(text, source_name, "plan", max_depth=MAX_NESTING, error=PlanFileError)
    reader = _Reader(source_name, aliases or {})
    reader.check_format(doc)
    return reader.plan(doc)


def read_subtree(
    doc: Any, file: str, fields: tuple[str, ...], aliases: Mapping[str, str] | None = None
) -> SubtreeSpec:
    """A subtree definition from a parsed document (a library file's body).

    Args:
        doc: the parsed JSON object.
        file: the file, for error messages.
        fields: the fields the object may have (the definition's and the file header's).
        aliases: former operation ids -> current ids.

    Raises:
        PlanFileError: the document is not a subtree definition.
    """
    return _Reader(file, aliases or {}).subtree(doc, "$", fields)


def load_plan(path: str | os.PathLike[str], aliases: Mapping[str, str] | None = None) -> PlanSpec:
    """Read a plan file.

    Args:
        path: the ``*.costar.json`` file.
        aliases: former operation ids -> current ids (``OperationSource.aliases()``).

    Returns:
        The plan.

    Raises:
        PlanFileError: the file is missing, unreadable, or not a plan this program reads.
    """
    file = os.fspath(path)
    doc = read_json_file(file, "plan", max_depth=MAX_NESTING, error=PlanFileError)
    reader = _Reader(file, aliases or {})
    reader.check_format(doc)
    return reader.plan(doc)


def plan_scene(path: str | os.PathLike[str]) -> str | None:
    """The simulated scene a plan file names (its ``scene``), or None: what a cell must open
    before the plan is loaded. A file that cannot be read is left to :func:`load_plan`,
    which says what is wrong with it.
    """
    try:
        scene = read_json_file(path).get("scene")
    except (JsonFileError, AttributeError):
        return None
    return scene if isinstance(scene, str) and scene else None
