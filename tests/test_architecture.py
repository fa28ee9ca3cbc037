"""The module graph: no import cycle, no private name imported from another module.

The dependency direction between the packages is declared as import-linter contracts
(``[tool.importlinter]`` in pyproject.toml, run by ``tests/test_import_contracts.py``).
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_resources_holds_data_and_its_locator_only() -> None:
    """No generator in the shipped package: its only Python is resources/__init__.py (the
    generators of its files live in tools/generators, which nothing shipped imports: a
    contract in pyproject.toml).
    """
    code = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "resources").rglob("*.py"))
    assert code == ["resources/__init__.py"]


# --------------------------------------------------------------------------- the module graph

PACKAGES = ("engine", "capabilities", "instructor_app")


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _runtime_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement, lazy ones included, except those under ``if TYPE_CHECKING:``."""
    found: list[ast.Import | ast.ImportFrom] = []
    stack: list[ast.AST] = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
        else:
            stack.extend(ast.iter_child_nodes(node))
    return found


def _base_of(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """The absolute module a ``from ... import`` reads from (relative imports resolved)."""
    if node.level == 0:
        return node.module or ""
    parts = module.split(".")
    keep = len(parts) - node.level + (1 if is_package else 0)
    base = ".".join(parts[:keep])
    return f"{base}.{node.module}" if node.module else base


def _pop_group(stack: list[str], on_stack: set[str], node: str) -> list[str]:
    """Pops Tarjan's stack down to ``node``: the strongly connected group it is the root of."""
    group = []
    while True:
        member = stack.pop()
        on_stack.discard(member)
        group.append(member)
        if member == node:
            return group


class ModuleGraph:
    """The project's modules and, for each, the project modules and names it imports."""

    def __init__(self, root: Path, packages: tuple[str, ...] = PACKAGES) -> None:
        self.files: dict[str, Path] = {}
        for package in packages:
            for path in sorted((root / package).rglob("*.py")):
                self.files[_module_name_in(root, path)] = path
        self.edges: dict[str, set[str]] = {name: set() for name in self.files}
        self.private: list[str] = []
        for name, path in self.files.items():
            self._read(name, path)

    def _read(self, name: str, path: Path) -> None:
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        is_package = path.name == "__init__.py"
        for node in _runtime_imports(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    self._edge(name, alias.name)
                continue
            base = _base_of(node, name, is_package)
            for alias in node.names:
                target = f"{base}.{alias.name}"
                if target in self.files:
                    self._edge(name, target)
                    continue
                self._edge(name, base)
                if alias.name.startswith("_") and base in self.files and base != name:
                    self.private.append(f"{name} imports {alias.name} from {base}")

    def _edge(self, source: str, target: str) -> None:
        if target in self.files and target != source:
            self.edges[source].add(target)

    def cycles(self) -> list[list[str]]:
        """One cycle (first module repeated at the end) per strongly connected group."""
        index: dict[str, int] = {}
        low: dict[str, int] = {}
        stack: list[str] = []
        on_stack: set[str] = set()
        groups: list[list[str]] = []

        def visit(start: str) -> None:  # Tarjan, iterative (no recursion limit)
            work = [(start, iter(sorted(self.edges[start])))]
            index[start] = low[start] = len(index)
            stack.append(start)
            on_stack.add(start)
            while work:
                node, children = work[-1]
                child = next(children, None)
                if child is None:
                    work.pop()
                    if work:
                        low[work[-1][0]] = min(low[work[-1][0]], low[node])
                    if low[node] == index[node]:
                        group = _pop_group(stack, on_stack, node)
                        if len(group) > 1:
                            groups.append(sorted(group))
                elif child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(self.edges[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])

        for module in sorted(self.edges):
            if module not in index:
                visit(module)
        return [self._cycle_in(set(group)) for group in sorted(groups)]

    def _cycle_in(self, group: set[str]) -> list[str]:
        """A shortest cycle through the first module of a strongly connected group."""
        start = min(group)
        paths = {start: [start]}
        frontier = [start]
        while frontier:
            following = []
            for node in frontier:
                for child in sorted(self.edges[node] & group):
                    if child == start:
                        return paths[node] + [start]
                    if child not in paths:
                        paths[child] = paths[node] + [child]
                        following.append(child)
            frontier = following
        raise AssertionError("a strongly connected group without a cycle")


def _module_name_in(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_no_import_cycle_between_modules() -> None:
    cycles = ModuleGraph(ROOT).cycles()
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def test_no_module_imports_a_private_name_of_another() -> None:
    private = ModuleGraph(ROOT).private
    assert not private, "\n".join(private)


def _project(tmp_path: Path, files: dict[str, str]) -> ModuleGraph:
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return ModuleGraph(tmp_path, ("pkg",))


def test_the_graph_finds_cycles_and_private_names(tmp_path: Path) -> None:
    graph = _project(
        tmp_path,
        {
            "pkg/__init__.py": "",
            "pkg/a.py": "from pkg.b import thing\n",
            "pkg/b.py": "def f():\n    from . import c\n",
            "pkg/c.py": "import pkg.a\nfrom pkg.d import _helper\n",
            "pkg/d.py": (
                "from typing import TYPE_CHECKING\n"
                "if TYPE_CHECKING:\n    from pkg.a import thing\n"
                "from ._inner import x\n"
            ),
            "pkg/sub/__init__.py": "from .. import d\nfrom .e import y\n",
            "pkg/sub/e.py": "from pkg.sub import z\n",
        },
    )
    assert graph.cycles() == [
        ["pkg.a", "pkg.b", "pkg.c", "pkg.a"],
        ["pkg.sub", "pkg.sub.e", "pkg.sub"],
    ]
    assert graph.private == ["pkg.c imports _helper from pkg.d"]
    assert graph.edges["pkg.sub"] == {"pkg.d", "pkg.sub.e"}
