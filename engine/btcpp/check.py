"""An imported plan checked by the project's own rules before it is written.

The XML reader reads what the file says; whether that makes a plan the project accepts is
decided where it is for every plan: the plan file's writer and reader
(:mod:`engine.files`: what ``load_plan`` reads back) and plan validation
(:func:`engine.validation.validate_plan`, what ``costar validate`` runs). Their problems are
reported at the XML line the part came from. What depends on a cell (whether an operation's
capability is available there) is left out: import has no cell.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from engine.btcpp.errors import XmlFileError, XmlProblem
from engine.btcpp.imported import XmlImport
from engine.files import PlanFileError, dump_plan, loads_plan
from engine.operations import Availability, Operation, OperationManifest, OperationSource
from engine.validation import ERROR, Problem, validate_plan

__all__ = ["AnyCell", "checked_plan_text"]

_EXPECTED = "a plan costar validate accepts"


class AnyCell:
    """An operation source whose operations are all available: validation without a cell.

    Args:
        source: the operations (manifests, aliases) of the installed capabilities.
    """

    def __init__(self, source: OperationSource) -> None:
        self._source = source

    def manifest(self, op_id: str) -> OperationManifest:
        return self._source.manifest(op_id)

    def availability(self, op_id: str) -> Availability:
        return Availability()

    def create(self, op_id: str) -> Operation:
        return self._source.create(op_id)

    def aliases(self) -> Mapping[str, str]:
        return self._source.aliases()

    def manifests(self) -> list[OperationManifest]:
        return self._source.manifests()


def checked_plan_text(imported: XmlImport, source: OperationSource) -> str:
    """The plan file text of an imported plan, once the project's rules accept it.

    The text is read back as ``load_plan`` would read the file, and the plan read back is
    validated (every operation counted as available).

    Args:
        imported: the plan and the lines it came from.
        source: the installed capabilities' operations (a cell-less registry).

    Raises:
        XmlFileError: every error found, each at the XML line of the node, parameter or
            subtree concerned (the ``<root>`` line for the plan as a whole).
    """
    file, lines = imported.file, imported.lines
    try:
        text = dump_plan(imported.plan)
        plan = loads_plan(text, file)
    except PlanFileError as exc:
        where = f"{exc.json_path}: " if exc.json_path else ""
        got = f"{where}expected {exc.expected}, got {exc.got}"
        line = _json_path_line(exc.json_path, imported)
        raise XmlFileError(file, [XmlProblem(line, "a plan the plan file can hold", got)]) from None
    try:
        problems = validate_plan(plan, AnyCell(source))
    except RecursionError:  # subtrees that run subtrees, hundreds deep
        got = "subtree instances nested too deep to check"
        raise XmlFileError(file, [XmlProblem(lines.root, _EXPECTED, got)]) from None
    errors = [p for p in problems if p.severity == ERROR]
    if errors:
        raise XmlFileError(
            file, [XmlProblem(_line(p, imported), _EXPECTED, _got(p)) for p in errors]
        )
    return text


def _line(problem: Problem, imported: XmlImport) -> int:
    lines = imported.lines
    if problem.node_id is not None:
        return lines.nodes.get(problem.node_id, lines.root)
    if problem.path == "parameters" and problem.field is not None:
        return lines.parameters.get(problem.field, lines.root)
    return lines.root


_PART = re.compile(r"\$\.(?:(parameters)\[(\d+)\]|(?:subtrees\[(\d+)\]\.?)?(tree)?)")
_CHILD = re.compile(r"\.children\[(\d+)\]")


def _json_path_line(path: str, imported: XmlImport) -> int:
    """The XML line of the part a plan file's JSON path names (``$.parameters[1]``,
    ``$.subtrees[0].tree.children[2]``...): its element, else the nearest one above.
    """
    plan, lines = imported.plan, imported.lines
    match = _PART.match(path or "")
    if match is None:
        return lines.root
    params, subtree, tree = match.group(2), match.group(3), match.group(4)
    if params is not None:
        index = int(params)
        name = plan.parameters[index].name if index < len(plan.parameters) else ""
        return lines.parameters.get(name, lines.root)
    line = lines.root
    node = plan.tree
    if subtree is not None and int(subtree) < len(plan.subtrees):
        sub = plan.subtrees[int(subtree)]
        line, node = lines.subtrees.get(sub.ref, line), sub.tree
    if tree is None or node is None:
        return line
    line = lines.nodes.get(node.id, line)
    for index in _CHILD.findall(path[match.end() :]):
        if int(index) >= len(node.children):
            break
        node = node.children[int(index)]
        line = lines.nodes.get(node.id, line)
    return line


def _got(problem: Problem) -> str:
    where = problem.path + (f" [{problem.field}]" if problem.field else "")
    return f"{where}: {problem.message}"
