"""``<include path="...">`` in BehaviorTree.CPP v4 files: the trees of another file join
the file's own, as BehaviorTree.CPP's ``XMLParser::loadDocImpl`` (src/xml_parsing.cpp) reads
them.

A relative path is taken from the folder of the file that holds the include (BehaviorTree.CPP
changes its current path to an included file's folder while it reads that file; a text read
with no file starts from the working folder). Included files may include others. Their
BehaviorTree elements join the root's, their TreeNodesModel's entries the root's model. A
problem found in an included tree is reported at the line of the ``<include>`` that brought
it in; one that keeps a file from being read names the file (and its line).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from engine.btcpp.xmltree import Element, XmlSyntaxError, parse_file

__all__ = ["expand_includes"]

Problem = Callable[[int, str, str], None]


def expand_includes(
    root: Element, folder: Path, problem: Problem, file: Path | None = None
) -> None:
    """Replace each ``<include>`` under ``root`` (of ``file``, if it was read from one) by
    the trees of the file it names.
    """
    _expand(root, folder, problem, () if file is None else (file.resolve(),), None)


def _expand(
    root: Element, folder: Path, problem: Problem, chain: tuple[Path, ...], at: int | None
) -> None:
    """``at``: the line of the outermost include (None: ``root`` is the file read)."""
    kept: list[Element] = []
    models: list[Element] = []  # the included files' TreeNodesModel elements
    for child in root.children:
        if child.tag != "include":
            kept.append(child)
            continue
        line = child.line if at is None else at
        included = _included(child, folder, problem, chain, line)
        if included is not None:
            path, other = included
            _expand(other, path.parent, problem, (*chain, path), line)
            kept += [_relined(e, line) for e in other.children if e.tag == "BehaviorTree"]
            models += [_relined(e, line) for e in other.children if e.tag == "TreeNodesModel"]
    own = next((c for c in kept if c.tag == "TreeNodesModel"), None)
    for model in models:
        if own is None:
            own = model
            kept.append(model)
        else:
            own.children += model.children
    root.children = kept


def _included(
    include: Element, folder: Path, problem: Problem, chain: tuple[Path, ...], line: int
) -> tuple[Path, Element] | None:
    """The file an ``<include>`` names and its root element; None after a problem."""
    text = include.attrs.get("path")
    if text is None:
        problem(line, "an <include> with a path attribute", "no path")
        return None
    if "ros_pkg" in include.attrs:
        problem(line, "an <include> without ros_pkg (a package path needs ROS)", repr(text))
        return None
    path = (folder / text).resolve()
    if path in chain:
        problem(line, "includes without a cycle", f"{text} includes itself again")
        return None
    try:
        with open(path, "rb") as handle:
            other = parse_file(handle)
    except OSError as exc:
        problem(line, f"a readable file for <include path={text!r}>", exc.strerror or str(exc))
        return None
    except XmlSyntaxError as exc:
        problem(line, f"well-formed XML in {text}", f"line {exc.line}: {exc}")
        return None
    if other.tag != "root":
        problem(line, f'a <root BTCPP_format="4"> element in {text}', f"<{other.tag}>")
        return None
    return path, other


def _relined(element: Element, line: int) -> Element:
    """``element`` with every line set to ``line`` (the include's, in the file read)."""
    element.line = line
    for child in element.children:
        _relined(child, line)
    return element
