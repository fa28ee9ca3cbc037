"""Writing plan files: deterministic JSON (save -> load -> save is byte-identical), atomically."""

from __future__ import annotations

import contextlib
import json
import os
import uuid
from pathlib import Path
from typing import Any

from engine.conditions import Condition
from engine.plan_format import (
    FORMAT,
    FORMAT_VERSION,
    MAX_TREE_DEPTH,
    PLAIN_FORMAT_VERSION,
    SUBTREES_FORMAT_VERSION,
    PlanFileError,
)
from engine.spec import (
    Binding,
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
from engine.types import ParamType, encode_value

__all__ = [
    "dump_json",
    "dump_plan",
    "encode_subtree",
    "has_conditions",
    "save_plan",
    "write_atomic",
]

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
    if node.subtree is not None:
        out["subtree"] = {"id": node.subtree.id, "version": node.subtree.version}
    # A binding with neither value nor reference says nothing: leave it out.
    params = {
        p: b
        for p, b in node.params.items()
        if b.ref is not None or b.type is not None or b.value is not None
    }
    if params:
        out["params"] = {port: _encode_binding(params[port]) for port in sorted(params)}
    conditions = _encode_conditions(node)
    if conditions:
        out["conditions"] = conditions
    if node.children:
        out["children"] = [_encode_node(child, depth + 1) for child in node.children]
    return out


def _encode_conditions(node: NodeSpec) -> dict[str, str]:
    """The node's conditions in their fixed order; an empty script says nothing."""
    given = {Condition(c): text for c, text in node.conditions.items()}
    return {c.value: given[c] for c in Condition if given.get(c, "").strip()}


def has_conditions(tree: NodeSpec | None) -> bool:
    """Whether any node of ``tree`` has a pre- or post-condition that says something."""
    return tree is not None and any(_encode_conditions(node) for _, node in tree.walk())


def _encode_layout(tree: NodeSpec | None, layout: dict[str, NodeLayout]) -> dict[str, Any]:
    """Tree order first, then entries of nodes not in the tree, by id: one canonical order."""
    walked = tree.walk() if tree is not None else iter(())
    order = [node.id for _, node in walked if node.id in layout]
    order += sorted(set(layout) - set(order))
    return {
        node_id: {
            "x": float(layout[node_id].x),
            "y": float(layout[node_id].y),
            "collapsed": bool(layout[node_id].collapsed),
        }
        for node_id in order
    }


def _encode_port(port: SubtreePort) -> dict[str, Any]:
    out: dict[str, Any] = {"name": port.name, "type": ParamType(port.type).value}
    if port.doc:
        out["doc"] = port.doc
    if port.default is not None:
        out["default"] = _encode_typed(port.type, port.default)
    return out


def encode_subtree(subtree: SubtreeSpec) -> dict[str, Any]:
    """The JSON object of a subtree definition (a plan's "subtrees" entry, a library file's body)."""
    return {
        "id": subtree.id,
        "name": subtree.name,
        "version": int(subtree.version),
        "date": subtree.date,
        "description": subtree.description,
        "inputs": [_encode_port(port) for port in subtree.inputs],
        "outputs": [_encode_port(port) for port in subtree.outputs],
        "shared_names": list(subtree.shared_names),
        "tree": _encode_node(subtree.tree, 1),
        "layout": {"nodes": _encode_layout(subtree.tree, subtree.layout)},
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
    uses_subtrees = bool(plan.subtrees) or any(
        node.kind is NodeKind.SUBTREE for _, node in plan.walk()
    )
    if has_conditions(plan.tree) or any(has_conditions(s.tree) for s in plan.subtrees):
        version = FORMAT_VERSION
    else:
        version = SUBTREES_FORMAT_VERSION if uses_subtrees else PLAIN_FORMAT_VERSION
    doc = {
        "format": FORMAT,
        "format_version": version,
        "id": plan.id,
        "name": plan.name,
        "description": plan.description,
        "run_policy": RunPolicy(plan.run_policy).value,
        **(
            {"give_up_after": plan.give_up_after}
            if plan.give_up_after != DEFAULT_GIVE_UP_AFTER
            else {}
        ),
        **({"reset_cell": True} if plan.reset_cell else {}),
        **({"scene": plan.scene} if plan.scene else {}),
        "parameters": [_encode_parameter(decl) for decl in plan.parameters],
        "tree": None if plan.tree is None else _encode_node(plan.tree, 1),
        "waypoints": [encode_value(waypoint) for waypoint in plan.waypoints],
        "objects": list(plan.objects),
        "layout": {"nodes": _encode_layout(plan.tree, plan.layout)},
        **({"subtrees": [encode_subtree(s) for s in plan.subtrees]} if plan.subtrees else {}),
    }
    return dump_json(doc, "<plan>")


def dump_json(doc: dict[str, Any], what: str) -> str:
    """Deterministic JSON text (indent 2, trailing newline) of a document.

    Raises:
        PlanFileError: the document holds a NaN or infinite number.
    """
    try:
        return json.dumps(doc, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    except ValueError as exc:
        raise PlanFileError(
            what, "", "finite numbers (JSON has no NaN or Infinity)", str(exc)
        ) from exc


def save_plan(plan: PlanSpec, path: str | os.PathLike[str]) -> None:
    """Write a plan file atomically: a temporary file in the same folder, fsync, rename.

    A failure at any point leaves the previous file as it was.

    Raises:
        PlanFileError: the plan cannot be encoded or the file cannot be written.
    """
    write_atomic(Path(os.fspath(path)), dump_plan(plan).encode("utf-8"))


def write_atomic(target: Path, data: bytes) -> None:
    """Replace ``target`` with ``data`` atomically (a synced temporary file renamed over it),
    keeping its permissions.
    """
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
