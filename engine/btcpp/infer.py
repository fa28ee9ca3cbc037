"""The ports of a subtree whose file declares no model for it (XML that BehaviorTree.CPP or
Groot2 wrote keeps no ``<SubTree>`` model): the names its instances remap, read or written
by the operations inside.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping

from engine.btcpp.names import decode_port
from engine.btcpp.xmltree import Element
from engine.conditions import Condition
from engine.operations import Direction
from engine.script import ScriptSyntaxError, parse_script, script_names
from engine.spec import SubtreePort
from engine.types import ParamType

__all__ = ["PortOf", "autoremapped", "infer_subtree_ports", "instances_of", "names_used"]

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
    operation inside writes is an output of that port's type, as is one that only scripts
    write (Any); any other an input, typed by the first port that reads it (Any when none
    says: BehaviorTree.CPP's remapped entries take any type).
    """
    names = _remapped(instances)
    written: dict[str, ParamType] = {}
    read: dict[str, ParamType] = {}
    scripted = _script_names(tree)
    for name in names:
        if name in scripted[1] and name not in scripted[0]:
            written[name] = ParamType.ANY
    for element in _walk(tree):
        for attr, value in element.attrs.items():
            if not (value.startswith("{") and value.endswith("}")) or value[1:-1] not in names:
                continue
            known = port_of(element, attr)
            if known is not None:
                into = written if known[0] is Direction.OUT else read
                into.setdefault(value[1:-1], known[1])
    inputs = [SubtreePort(n, read.get(n, ParamType.ANY)) for n in names if n not in written]
    outputs = [SubtreePort(n, written[n]) for n in names if n in written]
    return inputs, outputs


_SCRIPT_PORTS = {("Script", "code"), ("ScriptCondition", "code"), ("Precondition", "if")}
# Ports that name an entry as it is, NAME as well as {NAME}.
_ENTRY_PORTS = {
    ("SkipUnlessUpdated", "entry"),
    ("WaitValueUpdate", "entry"),
    ("WasEntryUpdated", "entry"),
    ("SetBlackboard", "output_key"),
}  # not UnsetBlackboard's key: BehaviorTree.CPP's unset looks in the subtree's own entries
_CONDITION_ATTRS = frozenset(c.attribute for c in Condition)


def _script_names(tree: Element) -> tuple[set[str], set[str]]:
    """(names read, names written) by the scripts of a tree (Script, ScriptCondition, pre-
    and post-conditions; a script that does not parse is reported where it is read).
    """
    reads: set[str] = set()
    writes: set[str] = set()
    for element in _walk(tree):
        for attr, value in element.attrs.items():
            if (element.tag, attr) in _SCRIPT_PORTS or attr in _CONDITION_ATTRS:
                try:
                    names = script_names(parse_script(value))
                except ScriptSyntaxError:
                    continue
                reads.update(names.reads)
                writes.update(names.writes)
    return reads, writes


def autoremapped(instance: Element) -> bool:
    """True for a ``<SubTree _autoremap="true">`` (BehaviorTree.CPP reads it as a bool)."""
    return instance.attrs.get("_autoremap", "false").strip().lower() in ("true", "1")


def names_used(tree_id: str, trees: Mapping[str, Element]) -> list[str]:
    """The blackboard names a tree uses (``{key}`` ports, scripts, pre- and post-conditions),
    with those of the subtrees it runs with ``_autoremap``, as BehaviorTree.CPP's autoremap
    shares them: every name but those starting with ``_`` (private to the subtree).
    """
    found: dict[str, None] = {}
    stack, seen = [tree_id], {tree_id}
    while stack:
        tree = trees.get(stack.pop())
        for element in _walk(tree) if tree is not None else ():
            for attr, value in element.attrs.items():
                for name in _names_in(element.tag, attr, value):
                    found.setdefault(name.lstrip("@"), None)
            inner = element.attrs.get("ID", "")
            if element.tag == "SubTree" and autoremapped(element) and inner not in seen:
                seen.add(inner)
                stack.append(inner)
    return [name for name in found if name and not name.startswith("_")]


def _names_in(tag: str, attr: str, value: str) -> list[str]:
    if value.startswith("{") and value.endswith("}") and value != "{=}":
        return [value[1:-1].strip()]
    if (tag, attr) in _ENTRY_PORTS:
        return [value.strip()]
    if (tag, attr) in _SCRIPT_PORTS or attr in _CONDITION_ATTRS:
        try:
            names = script_names(parse_script(value))
        except ScriptSyntaxError:
            return []  # the node's reading reports it
        return [*names.reads, *names.writes]
    return []
