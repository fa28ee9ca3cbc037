"""The ports of a subtree whose file declares no model for it (XML that BehaviorTree.CPP or
Groot2 wrote keeps no ``<SubTree>`` model): the names its instances remap, read or written
by the operations inside.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from engine.btcpp.names import decode_port
from engine.btcpp.xmltree import Element
from engine.operations import Direction
from engine.spec import SubtreePort
from engine.types import ParamType

__all__ = ["PortOf", "infer_subtree_ports", "instances_of"]

# (element, attribute) -> the direction and type of that port of the element's node, if known
PortOf = Callable[[Element, str], tuple[Direction, ParamType] | None]


def _walk(element: Element) -> Iterator[Element]:
    stack = [element]
    while stack:
        here = stack.pop()
        yield here
        stack.extend(reversed(here.children))


def instances_of(tree_id: str, trees: list[Element]) -> list[Element]:
    """Every ``<SubTree ID=tree_id>`` in the given BehaviorTrees, in file order."""
    return [
        e for t in trees for e in _walk(t) if e.tag == "SubTree" and e.attrs.get("ID") == tree_id
    ]


def _remapped(instances: list[Element]) -> list[str]:
    names: dict[str, None] = {}
    for instance in instances:
        for attr in instance.attrs:
            if attr in ("ID", "name") or attr.startswith("_"):
                continue
            try:
                names[decode_port(attr)] = None
            except ValueError:
                continue  # reported where the instance is read
    return list(names)


def infer_subtree_ports(
    tree: Element, instances: list[Element], port_of: PortOf
) -> tuple[list[SubtreePort], list[SubtreePort]]:
    """(inputs, outputs) of a subtree from its instances and the nodes inside: a name an
    operation inside writes is an output of that port's type, any other an input, typed by
    the first port that reads it (Text when none says).
    """
    names = _remapped(instances)
    written: dict[str, ParamType] = {}
    read: dict[str, ParamType] = {}
    for element in _walk(tree):
        for attr, value in element.attrs.items():
            if not (value.startswith("{") and value.endswith("}")) or value[1:-1] not in names:
                continue
            known = port_of(element, attr)
            if known is not None:
                into = written if known[0] is Direction.OUT else read
                into.setdefault(value[1:-1], known[1])
    inputs = [SubtreePort(n, read.get(n, ParamType.TEXT)) for n in names if n not in written]
    outputs = [SubtreePort(n, written[n]) for n in names if n in written]
    return inputs, outputs
