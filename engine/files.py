"""Plan files (``*.costar.json``): versioned JSON, read with clear errors, written atomically.

A plan file is plain JSON (DESIGN.md section 6)::

    {"format": "costar-plan", "format_version": 1, "id": ..., "name": ..., "description": ...,
     "run_policy": "once", "parameters": [...], "tree": {...} | null, "waypoints": [...],
     "objects": [...], "layout": {"nodes": {node id: {"x": ..., "y": ..., "collapsed": ...}}}}

Reading checks the shape of everything and names the file, the JSON path and what was
expected; unknown fields are refused so that typos are caught. Renamed node kinds
(:data:`KIND_ALIASES`) and renamed operations (the ``aliases`` argument) keep loading under
their new names. Nothing in a file is executed. Writing is deterministic (fixed key order,
indent 2, trailing newline, floats as ``repr``), so save -> load -> save gives the same bytes.

The reader accepts a decorator without a child and an empty composite: the editor saves
half-built plans. Validation (:mod:`engine.validation`) reports them, and a plan with such
errors does not start.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import types
import uuid
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NoReturn

from engine.errors import EngineError
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
from engine.types import ParamType, ValueError_, Waypoint, decode_value, encode_value

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "KIND_ALIASES",
    "MAX_TREE_DEPTH",
    "PLAN_SUFFIX",
    "READABLE_VERSIONS",
    "PlanFileError",
    "dump_plan",
    "load_plan",
    "loads_plan",
    "save_plan",
]

FORMAT = "costar-plan"
FORMAT_VERSION = 1
READABLE_VERSIONS: tuple[int, ...] = (1,)
PLAN_SUFFIX = ".costar.json"
# Python's JSON reader and writer recurse about twice per tree level; 400 levels stay well
# inside the default recursion limit of 1000 even when called from a deep GUI stack.
MAX_TREE_DEPTH = 400

KIND_ALIASES: Mapping[str, str] = types.MappingProxyType(
    {"fallback": "selector", "reactive_fallback": "reactive_selector"}
)

_TOP_FIELDS: tuple[str, ...] = ("format", "format_version", "id", "name", "description")
_TOP_FIELDS += ("run_policy", "parameters", "tree", "waypoints", "objects", "layout")
_NODE_FIELDS = ("id", "kind", "name", "op", "params", "config", "children")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


class PlanFileError(EngineError):
    """A plan file that cannot be read or written, with where and what was expected.

    Attributes:
        file: the file as given (``"<string>"`` for text).
        json_path: where in the document (``$.tree.children[1].params.target``); empty when
            the problem is the file as a whole.
        expected: what should have been there.
        got: what was there.
        line: line of a JSON syntax error (1-based), else None.
        column: column of a JSON syntax error (1-based), else None.
    """

    def __init__(
        self,
        file: str,
        json_path: str,
        expected: str,
        got: str,
        line: int | None = None,
        column: int | None = None,
    ) -> None:
        self.file = file
        self.json_path = json_path
        self.expected = expected
        self.got = got
        self.line = line
        self.column = column
        where = [Path(file).name or file]
        if line is not None:
            where.append(f"line {line} column {column}")
        if json_path:
            where.append(json_path)
        super().__init__(f"{': '.join(where)}: expected {expected}, got {got}")


def describe(value: Any) -> str:
    """A short plain description of a JSON value for error messages."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, str):
        text = value if len(value) <= 40 else value[:37] + "..."
        return f"the text {text!r}"
    if isinstance(value, list):
        return f"a list of {len(value)} item{'' if len(value) == 1 else 's'}"
    if isinstance(value, dict):
        keys = ", ".join(list(value)[:6]) + (", ..." if len(value) > 6 else "")
        return f"an object with {keys}" if value else "an empty object"
    return type(value).__name__


def at(path: str, key: str | int) -> str:
    """The JSON path of ``key`` inside ``path``: ``$.tree``, ``$.tree.children[0]``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if _IDENT.match(key) else f"{path}[{json.dumps(key)}]"


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
        doc = self.fields(doc, "$", _TOP_FIELDS, required=("format", "format_version"))
        plan = PlanSpec(
            id=self.text(doc.get("id", new_id()), "$.id", nonempty=True),
            name=self.text(doc.get("name", ""), "$.name"),
            description=self.text(doc.get("description", ""), "$.description"),
            run_policy=RunPolicy(
                self.choice(
                    doc.get("run_policy", "once"), "$.run_policy", [p.value for p in RunPolicy]
                )
            ),
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
        obj = self.fields(value, path, _NODE_FIELDS, required=("id", "kind"))
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
        elif "op" in obj or "params" in obj:
            field = "op" if "op" in obj else "params"
            self.fail(
                at(path, field),
                f"no {field}: only operation nodes have one",
                f"a {kind.value} node with {field}",
            )
        params = self.mapping(obj.get("params", {}), at(path, "params"), "port -> binding")
        node.params = {
            port: self.binding(b, at(at(path, "params"), port)) for port, b in params.items()
        }
        node.config = self.config(obj.get("config", {}), at(path, "config"))
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

    def config(self, value: Any, path: str) -> dict[str, Any]:
        obj = self.mapping(value, path, "setting -> value")
        for key, setting in obj.items():
            if isinstance(setting, (list, dict)):
                self.fail(at(path, key), "a number, text, true/false or null", describe(setting))
        return dict(obj)

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


# --------------------------------------------------------------------------- writing


def _encode_typed(ptype: ParamType, value: Any) -> Any:
    """A Number or Duration is read back as a float: write it as one, so the bytes stay put."""
    is_int = isinstance(value, int) and not isinstance(value, bool)
    if is_int and ParamType(ptype) in (ParamType.NUMBER, ParamType.DURATION):
        return float(value)
    return encode_value(value)


def _encode_binding(binding: Binding) -> dict[str, Any]:
    if binding.ref is not None:
        return {"ref": binding.ref}
    ptype = binding.type if binding.type is not None else ParamType.ANY
    return {"type": ParamType(ptype).value, "value": _encode_typed(ptype, binding.value)}


def _encode_node(node: NodeSpec, depth: int) -> dict[str, Any]:
    if depth > MAX_TREE_DEPTH:
        raise PlanFileError(
            "<plan>", "$.tree", f"a tree at most {MAX_TREE_DEPTH} levels deep", "a deeper tree"
        )
    out: dict[str, Any] = {"id": node.id, "kind": NodeKind(node.kind).value}
    if node.name:
        out["name"] = node.name
    if node.op is not None:
        out["op"] = node.op
    # A binding with neither value nor reference says nothing: leave it out.
    params = {
        p: b
        for p, b in node.params.items()
        if b.ref is not None or b.type is not None or b.value is not None
    }
    if params:
        out["params"] = {port: _encode_binding(params[port]) for port in sorted(params)}
    if node.config:
        out["config"] = {key: encode_value(node.config[key]) for key in sorted(node.config)}
    if node.children:
        out["children"] = [_encode_node(child, depth + 1) for child in node.children]
    return out


def _encode_layout(plan: PlanSpec) -> dict[str, Any]:
    """Tree order first, then entries of nodes not in the tree, by id: one canonical order."""
    order = [node.id for _, node in plan.walk() if node.id in plan.layout]
    order += sorted(set(plan.layout) - set(order))
    return {
        node_id: {
            "x": float(plan.layout[node_id].x),
            "y": float(plan.layout[node_id].y),
            "collapsed": bool(plan.layout[node_id].collapsed),
        }
        for node_id in order
    }


def _encode_parameter(decl: ParameterDecl) -> dict[str, Any]:
    out: dict[str, Any] = {"name": decl.name, "type": ParamType(decl.type).value}
    if decl.value is not None:
        out["value"] = _encode_typed(decl.type, decl.value)
    if decl.doc:
        out["doc"] = decl.doc
    return out


def dump_plan(plan: PlanSpec) -> str:
    """The plan file text of a plan: deterministic, indent 2, trailing newline.

    Raises:
        PlanFileError: the plan holds a NaN or infinite number, or is deeper than
            :data:`MAX_TREE_DEPTH`.
    """
    doc = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "id": plan.id,
        "name": plan.name,
        "description": plan.description,
        "run_policy": RunPolicy(plan.run_policy).value,
        "parameters": [_encode_parameter(decl) for decl in plan.parameters],
        "tree": None if plan.tree is None else _encode_node(plan.tree, 1),
        "waypoints": [encode_value(waypoint) for waypoint in plan.waypoints],
        "objects": list(plan.objects),
        "layout": {"nodes": _encode_layout(plan)},
    }
    try:
        return json.dumps(doc, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    except ValueError as exc:
        raise PlanFileError(
            "<plan>", "", "finite numbers (JSON has no NaN or Infinity)", str(exc)
        ) from exc


def save_plan(plan: PlanSpec, path: str | os.PathLike[str]) -> None:
    """Write a plan file atomically: a temporary file in the same folder, fsync, rename.

    A failure at any point leaves the previous file as it was.

    Raises:
        PlanFileError: the plan cannot be encoded or the file cannot be written.
    """
    _write_atomic(Path(os.fspath(path)), dump_plan(plan).encode("utf-8"))


def _write_atomic(target: Path, data: bytes) -> None:
    tmp = target.with_name(f".{target.name}.{uuid.uuid4().hex[:8]}.tmp")
    done = False
    try:
        # os.open applies the umask to 0o666, as a plain open() of the target would.
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        with contextlib.suppress(FileNotFoundError):
            os.chmod(tmp, os.stat(target).st_mode & 0o7777)  # keep the old file's permissions
        os.replace(tmp, target)
        done = True
    except OSError as exc:
        raise PlanFileError(
            str(target), "", "a place where the plan can be written", exc.strerror or str(exc)
        ) from exc
    finally:
        if not done:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    _sync_folder(target.parent)


def _sync_folder(folder: Path) -> None:
    """Make the rename itself durable where the system allows it (not on Windows)."""
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
