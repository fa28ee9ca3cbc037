"""Build the nodes of a generated plan or library, with ids that stay the same between runs.

Every generator of ``resources/`` builds its plans and subtrees with a :class:`PlanBuilder`
(a subclass adds a generator's own steps): node ids are uuid5 of the generator's namespace
and a running count within a scope, plan ids uuid5 of the namespace and the plan's name
(:func:`stable_id`), and every shipped subtree carries :data:`DATE`, so writing the files
again gives them byte for byte. ``write_library`` writes subtrees where the palette finds them.
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

__all__ = [
    "CELL_EXAMPLES",
    "CLEAR_STOP",
    "DATE",
    "EXAMPLES",
    "KITTING",
    "PICK_PLACE",
    "TENDING",
    "PlanBuilder",
    "fixed",
    "obj",
    "port",
    "stable_id",
    "subtree",
    "write_library",
]

DATE = "2026-11-24T00:00:00Z"  # the shipped subtrees' date: fixed, so they are written alike

# Each generator's uuid5 namespace: the ids in the files it wrote come from it, so a value
# never changes (a new generator gets a new one).
EXAMPLES = uuid.UUID("6f1c3d0e-8f61-4d0e-9a57-2b8f3c0d7e11")  # make_examples
CELL_EXAMPLES = uuid.UUID("0b7f2a4e-3c1d-4f5e-8a9b-6c7d8e9f0a1b")  # make_cell_examples
CLEAR_STOP = uuid.UUID("3f0c5b1e-8a47-4d2a-b6e1-5c9d2e7a4f10")  # make_clear_stop
KITTING = uuid.UUID("5d1c7a0e-2b4f-4c8e-9a3d-7e6f5a4b3c2d")  # make_kitting
TENDING = uuid.UUID("8f3e6a2c-1d4b-4e7a-9c5f-2b8d7e6a5c41")  # make_tending, tending_library
PICK_PLACE = uuid.UUID("c41e2d7a-6b3f-4a58-9e0d-1f7c3b5a2e96")  # make_pick_place


def stable_id(namespace: uuid.UUID, name: str) -> str:
    """The id of ``name`` in a generator's ``namespace``: the same on every run."""
    return uuid.uuid5(namespace, name).hex


class PlanBuilder:
    """Nodes whose ids are ``uuid5(namespace, f"{scope}/{n}")`` for n = 1, 2, ..."""

    def __init__(self, namespace: uuid.UUID, scope: str) -> None:
        self.namespace = namespace
        self.scope = scope
        self.count = 0

    def id(self) -> str:
        """The next id of the scope (a node takes its id once its children have theirs)."""
        self.count += 1
        return stable_id(self.namespace, f"{self.scope}/{self.count}")

    def node(
        self,
        kind: NodeKind,
        name: str,
        *children: NodeSpec,
        node_id: str | None = None,
        **config: Any,
    ) -> NodeSpec:
        """A logic node; ``config`` are its settings (``engine.kinds.setting``). ``node_id``:
        an id taken earlier with :meth:`id` (a tree numbered from its root down).
        """
        params = {k: setting(kind, k, v) for k, v in config.items()}
        return NodeSpec(kind, name, node_id or self.id(), params=params, children=list(children))

    def op(self, op: str, name: str, /, **params: Binding | str) -> NodeSpec:
        """An operation; a text parameter is a blackboard reference (a parameter may be
        called ``name``: the label is positional only).
        """
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
        scales the nominal speed and acceleration alike (default: left at the port's 1).
        """
        params: dict[str, Binding | str] = {
            "target": target if isinstance(target, str) else fixed(target, ParamType.WAYPOINT)
        }
        if reference:
            params["reference"] = reference
        if linear:
            params["mode"] = fixed("linear", ParamType.TEXT)
        if speed != 1.0:
            params |= {
                "speed": fixed(speed, ParamType.NUMBER),
                "accel": fixed(speed, ParamType.NUMBER),
            }
        return self.op("motion.move_to", name, **params)

    def instance(self, subtree: SubtreeSpec, name: str, /, **params: Binding | str) -> NodeSpec:
        """An instance of a library subtree; a text parameter is a blackboard reference."""
        return NodeSpec(
            NodeKind.SUBTREE, name, self.id(), params=_bound(params), subtree=subtree.ref
        )


def _bound(params: dict[str, Binding | str]) -> dict[str, Binding]:
    return {k: Binding.reference(v) if isinstance(v, str) else v for k, v in params.items()}


def fixed(value: Any, ptype: ParamType) -> Binding:
    """A fixed parameter value of type ``ptype``."""
    return Binding.fixed(value, ptype)


def obj(name: str) -> Binding:
    """The object model ``name``, as a fixed parameter."""
    return fixed(ObjectModel(name), ParamType.OBJECT)


def port(name: str, ptype: ParamType, doc: str, default: Any = None) -> SubtreePort:
    """A subtree port: its name, type, doc and default."""
    return SubtreePort(name, ptype, doc, default)


def subtree(key: str, name: str, description: str, tree: NodeSpec, **ports: Any) -> SubtreeSpec:
    """Version 1 of a shipped subtree; ``inputs`` and ``outputs`` are lists of ports."""
    return SubtreeSpec(
        key,
        name,
        tree,
        1,
        DATE,
        description,
        inputs=ports.get("inputs", []),
        outputs=ports.get("outputs", []),
    )


def write_library(folder: Path, subtrees: list[SubtreeSpec], root: Path) -> None:
    """Write each subtree to ``folder/<name>.subtree.json``; say which, relative to ``root``."""
    folder.mkdir(parents=True, exist_ok=True)
    for spec in subtrees:
        path = folder / f"{spec.name}.subtree.json"
        write_atomic(path, dump_subtree(spec).encode("utf-8"))
        print(f"wrote {path.relative_to(root)}")
