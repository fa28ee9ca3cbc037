"""Reading plan files: every shape checked, errors name the file, JSON path and expectation."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NoReturn

from engine.kinds import setting as kind_setting
from engine.plan_format import (
    FORMAT,
    FORMAT_VERSION,
    KIND_ALIASES,
    MAX_TREE_DEPTH,
    NODE_FIELDS,
    NODE_FIELDS_V1,
    READABLE_VERSIONS,
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
    new_id,
)
from engine.types import ParamType, ValueError_, Waypoint, decode_value

__all__ = ["load_plan", "loads_plan"]

V1_WAIT_OP = "timing.wait"  # format 1's operation for what is the Wait node

# --------------------------------------------------------------------------- reading


class _JsonObject(dict[str, Any]):
    """A parsed JSON object that remembers keys it had more than once (JSON keeps the last)."""

    duplicates: tuple[str, ...] = ()


class _ObjectHook:
    """Builds parsed JSON objects; marks (rare) objects that had a key twice."""

    def __init__(self) -> None:
        self.found_duplicates = False

    def __call__(self, pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        obj = dict(pairs)
        if len(obj) == len(pairs):
            return obj
        self.found_duplicates = True
        seen: set[str] = set()
        marked = _JsonObject(obj)
        for key, _ in pairs:
            if key in seen and key not in marked.duplicates:
                marked.duplicates += (key,)
            seen.add(key)
        return marked


class _NotFinite(ValueError):
    """NaN, Infinity or -Infinity in the text: Python reads them, JSON does not have them."""


def _no_constant(name: str) -> NoReturn:
    raise _NotFinite(name)


def _first_duplicate(doc: Any) -> tuple[str, str] | None:
    """(path, key) of the first key given twice in one object, in document order."""
    stack: list[tuple[str, Any]] = [("$", doc)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, dict):
            if getattr(value, "duplicates", ()):
                return path, value.duplicates[0]  # type: ignore[attr-defined]
            stack.extend((at(path, k), v) for k, v in reversed(value.items()))
        elif isinstance(value, list):
            stack.extend((at(path, i), v) for i, v in reversed(list(enumerate(value))))
    return None


class _Reader:
    """Turns a parsed document into a PlanSpec, failing at the first thing that is off."""

    def __init__(self, file: str, aliases: Mapping[str, str]) -> None:
        self.file = file
        self.aliases = aliases
        self.ids: dict[str, str] = {}  # node id -> JSON path of the node that has it
        self.version: object = FORMAT_VERSION  # of the file, known after check_format

    def fail(self, path: str, expected: str, got: str) -> NoReturn:
        raise PlanFileError(self.file, path, expected, got)

    def fields(
        self, value: Any, path: str, fields: tuple[str, ...], required: tuple[str, ...] = ()
    ) -> dict[str, Any]:
        if not isinstance(value, dict):
            self.fail(path, f"an object with {', '.join(required or fields)}", describe(value))
        for key in value:
            if key not in fields:
                self.fail(at(path, key), f"one of the fields {', '.join(fields)}", f"{key!r}")
        for key in required:
            if key not in value:
                self.fail(at(path, key), "a value here (it is required)", "nothing")
        return value

    def mapping(self, value: Any, path: str, what: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            self.fail(path, f"an object of {what}", describe(value))
        return value

    def text(self, value: Any, path: str, nonempty: bool = False) -> str:
        if not isinstance(value, str) or (nonempty and not value.strip()):
            self.fail(path, "a non-empty text" if nonempty else "a text", describe(value))
        return value

    def flag(self, value: Any, path: str) -> bool:
        if not isinstance(value, bool):
            self.fail(path, "true or false", describe(value))
        return value

    def items(self, value: Any, path: str, what: str) -> list[Any]:
        if not isinstance(value, list):
            self.fail(path, f"a list of {what}", describe(value))
        return value

    def unique(self, name: str, before: list[str], path: str) -> None:
        if name in before:
            self.fail(path, "a name not used before in this list", f"{name!r} a second time")

    def choice(self, value: Any, path: str, choices: list[str]) -> str:
        if value not in choices:
            self.fail(path, f"one of {', '.join(choices)}", describe(value))
        return str(value)

    def value(self, ptype: ParamType, value: Any, path: str) -> Any:
        try:
            return decode_value(ptype, value, path)
        except ValueError_ as exc:
            got = str(exc).partition(f"{exc.path}: expected {exc.expected}, got ")[2]
            raise PlanFileError(self.file, exc.path, exc.expected, got or "something else") from exc

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
            reset_cell=self.flag(doc.get("reset_cell", False), "$.reset_cell"),
        )
        if doc.get("tree") is not None:
            plan.tree = self.node(doc["tree"], "$.tree", 1)
        plan.parameters = self.parameters(doc.get("parameters", []), "$.parameters")
        plan.waypoints = self.waypoints(doc.get("waypoints", []), "$.waypoints")
        plan.objects = self.objects(doc.get("objects", []), "$.objects")
        plan.layout = self.layout(doc.get("layout", {"nodes": {}}), "$.layout")
        return plan

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
                at(path, "op"), "no op: only operation nodes have one", f"a {kind.value} node"
            )
        params = self.mapping(obj.get("params", {}), at(path, "params"), "port -> binding")
        node.params = {
            port: self.binding(b, at(at(path, "params"), port)) for port, b in params.items()
        }
        if self.version == 1:
            self.v1_settings(node, obj.get("config", {}), at(path, "config"))
        children = self.items(obj.get("children", []), at(path, "children"), "nodes")
        self.check_children(kind, len(children), at(path, "children"))
        for index, child in enumerate(children):
            node.children.append(self.node(child, at(at(path, "children"), index), depth + 1))
        return node

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
        source_name: the file name used in error messages.
        aliases: former operation ids -> current ids; the loaded spec holds current ids.

    Returns:
        The plan.

    Raises:
        PlanFileError: the text is not a plan this program reads.
    """
    try:
        hook = _ObjectHook()
        doc = json.loads(text, object_pairs_hook=hook, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        cut = exc.pos >= len(text.rstrip())
        got = "the end of the file: it is cut off" if cut else f"a syntax error ({exc.msg})"
        raise PlanFileError(source_name, "", "valid JSON", got, exc.lineno, exc.colno) from exc
    except _NotFinite as exc:
        raise PlanFileError(
            source_name, "", "finite numbers (JSON has no NaN or Infinity)", str(exc)
        ) from exc
    except ValueError as exc:  # a number too long to convert, for one
        raise PlanFileError(source_name, "", "valid JSON", str(exc)) from exc
    except RecursionError as exc:
        raise PlanFileError(
            source_name, "", f"a tree at most {MAX_TREE_DEPTH} levels deep", "deeper nesting"
        ) from exc
    reader = _Reader(source_name, aliases or {})
    reader.check_format(doc)
    duplicate = _first_duplicate(doc) if hook.found_duplicates else None
    if duplicate is not None:
        reader.fail(duplicate[0], "each field at most once in an object", f"{duplicate[1]!r} twice")
    return reader.plan(doc)


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
    try:
        data = Path(file).read_bytes()
    except FileNotFoundError as exc:
        raise PlanFileError(file, "", "a plan file", f"no file at {file}") from exc
    except OSError as exc:
        raise PlanFileError(file, "", "a readable plan file", exc.strerror or str(exc)) from exc
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise PlanFileError(
            file, "", "UTF-8 text", f"a byte that is not UTF-8 at offset {exc.start}"
        ) from exc
    return loads_plan(text, file, aliases)
