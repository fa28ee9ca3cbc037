"""Build the nodes of a generated library or plan, with ids that stay the same between runs.

The generators of the shipped library (``make_kitting.py``, ``make_tending.py``) build their
subtrees and plans with a :class:`PlanBuilder` each: node ids are uuid5 of the generator's own
namespace and a running count within a scope, so writing the files again gives them byte for
byte. ``write_library`` writes subtrees where the palette finds them.
"""

from __future__ import annotations

import uuid
from pathlib import Path
from typing import Any

from engine.kinds import setting
from engine.library import dump_subtree
from engine.plan_writer import write_atomic
from engine.spec import Binding, NodeKind, NodeSpec, SubtreePort, SubtreeSpec
from engine.types import ObjectModel, ParamType, Waypoint

__all__ = ["PlanBuilder", "fixed", "obj", "port", "subtree", "write_library"]

DATE = "2026-11-24T00:00:00Z"  # the shipped subtrees' date: fixed, so they are written alike


class PlanBuilder:
    """Nodes whose ids are ``uuid5(namespace, f"{scope}/{n}")`` for n = 1, 2, ..."""

    def __init__(self, namespace: uuid.UUID, scope: str) -> None:
        self.namespace = namespace
        self.scope = scope
        self.count = 0

    def id(self) -> str:
        self.count += 1
        return uuid.uuid5(self.namespace, f"{self.scope}/{self.count}").hex

    def node(self, kind: NodeKind, name: str, *children: NodeSpec, **config: Any) -> NodeSpec:
        params = {k: setting(kind, k, v) for k, v in config.items()}
        return NodeSpec(kind, name, self.id(), params=params, children=list(children))

    def op(self, op: str, name: str, **params: Binding | str) -> NodeSpec:
        """An operation; a text parameter is a blackboard reference."""
        return NodeSpec(NodeKind.OPERATION, name, self.id(), op=op, params=_bound(params))

    def move(
        self,
        name: str,
        target: Waypoint | str,
        reference: str = "",
        linear: bool = False,
        speed: float = 1.0,
    ) -> NodeSpec:
        """``motion.move_to`` a waypoint (or the one a blackboard entry names); ``speed``
        scales the nominal speed and acceleration alike (default: left at the port's 1)."""
        params: dict[str, Binding | str] = {
            "target": target if isinstance(target, str) else fixed(target, ParamType.WAYPOINT)
        }
        if reference:
            params["reference"] = reference
        if linear:
            params["mode"] = fixed("linear", ParamType.TEXT)
        if speed != 1.0:
            params |= {"speed": fixed(speed, ParamType.NUMBER),
                       "accel": fixed(speed, ParamType.NUMBER)}  # fmt: skip
        return self.op("motion.move_to", name, **params)

    def instance(self, subtree: SubtreeSpec, name: str, **params: Binding | str) -> NodeSpec:
        """An instance of a library subtree; a text parameter is a blackboard reference."""
        return NodeSpec(
            NodeKind.SUBTREE, name, self.id(), params=_bound(params), subtree=subtree.ref
        )


def _bound(params: dict[str, Binding | str]) -> dict[str, Binding]:
    return {k: Binding.reference(v) if isinstance(v, str) else v for k, v in params.items()}


def fixed(value: Any, ptype: ParamType) -> Binding:
    return Binding.fixed(value, ptype)


def obj(name: str) -> Binding:
    """The object model ``name``, as a fixed parameter."""
    return fixed(ObjectModel(name), ParamType.OBJECT)


def port(name: str, ptype: ParamType, doc: str, default: Any = None) -> SubtreePort:
    return SubtreePort(name, ptype, doc, default)


def subtree(key: str, name: str, description: str, tree: NodeSpec, **ports: Any) -> SubtreeSpec:
    """Version 1 of a shipped subtree; ``inputs`` and ``outputs`` are lists of ports."""
    return SubtreeSpec(
        key, name, tree, 1, DATE, description,
        inputs=ports.get("inputs", []), outputs=ports.get("outputs", []),
    )  # fmt: skip


def write_library(folder: Path, subtrees: list[SubtreeSpec], root: Path) -> None:
    """Write each subtree to ``folder/<name>.subtree.json``; say which, relative to ``root``."""
    folder.mkdir(parents=True, exist_ok=True)
    for spec in subtrees:
        path = folder / f"{spec.name}.subtree.json"
        write_atomic(path, dump_subtree(spec).encode("utf-8"))
        print(f"wrote {path.relative_to(root)}")
