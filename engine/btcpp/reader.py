"""Reading BehaviorTree.CPP v4 XML into a plan; every problem is reported with its line."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from engine.btcpp.errors import XmlFileError, XmlProblem
from engine.btcpp.imported import XmlImport
from engine.btcpp.includes import expand_includes
from engine.btcpp.infer import autoremapped, infer_subtree_ports, instances_of, names_used
from engine.btcpp.logic import LOGIC_BY_MODEL, LogicModel
from engine.btcpp.names import decode_id, decode_port
from engine.btcpp.read_parts import Model, ReaderBase, model_remaps, read_models
from engine.btcpp.writer import UNUSED_OUTPUT
from engine.btcpp.xmltree import Element, XmlSyntaxError, XmlTooLarge, parse, parse_file
from engine.conditions import Condition
from engine.kinds import kind_port
from engine.kinds import setting as kind_setting
from engine.operations import Direction, OperationManifest
from engine.spec import (
    KIND_CATEGORY,
    Binding,
    Category,
    NodeKind,
    NodeLayout,
    NodeSpec,
    PlanSpec,
    SubtreeSpec,
    new_id,
)
from engine.types import ParamType

__all__ = ["import_xml", "load_xml", "read_xml"]

_EXPLICIT = ("Action", "Condition", "Control", "Decorator")
# BehaviorTree.CPP's pre- and post-conditions (_skipIf ...): attribute -> ours.
_CONDITIONS: Mapping[str, Condition] = {c.attribute: c for c in Condition}


class _Reader(ReaderBase):
    def __init__(
        self, manifests: Mapping[str, OperationManifest] | None, file: Path | None = None
    ) -> None:
        super().__init__()
        self.manifests = manifests
        self.file = file  # the file read (None: a text)
        self.folder = file.parent if file is not None else Path.cwd()  # <include> paths start
        self.subtrees: dict[str, SubtreeSpec] = {}  # BehaviorTree ID -> definition
        self.ids: set[str] = set()
        self.foreign = False  # True: not written by us (no CostarPlan element)

    def plan(self, root: Element) -> PlanSpec:
        if root.tag != "root":
            self.problem(root.line, 'a <root BTCPP_format="4"> element', f"<{root.tag}>")
            return PlanSpec()
        if root.attrs.get("BTCPP_format", "4") != "4":
            self.problem(root.line, 'BTCPP_format="4"', repr(root.attrs["BTCPP_format"]))
        own_trees = [c.attrs.get("ID", "") for c in root.children if c.tag == "BehaviorTree"]
        expand_includes(root, self.folder, self.problem, self.file)
        groups: dict[str, list[Element]] = {}
        for child in root.children:
            groups.setdefault(child.tag, []).append(child)
        self.lines.root = root.line
        self.models = read_models(self._the_one(groups, "TreeNodesModel"), self.problem)
        data = self._the_one(groups, "CostarPlan")
        self.foreign = data is None
        trees = self._trees(groups.get("BehaviorTree", []))
        main_id = self._main_id(root, data, trees, own_trees)
        plan = PlanSpec(name=main_id or "")
        self._read_subtrees(trees, main_id)
        if main_id is not None:
            plan.tree = self._root_node(trees[main_id], plan.layout)
        plan.subtrees = list(self.subtrees.values())
        if data is not None:
            self._plan_data(data, plan)
        return plan

    def _the_one(self, groups: dict[str, list[Element]], tag: str) -> Element | None:
        """The first ``tag`` element under the root; a second one is a problem."""
        for extra in groups.get(tag, [])[1:]:
            self.problem(extra.line, f"one <{tag}>", "a second one")
        return next(iter(groups.get(tag, [])), None)

    def _trees(self, elements: list[Element]) -> dict[str, Element]:
        """The BehaviorTree elements by ID (the first of each ID)."""
        trees: dict[str, Element] = {}
        for index, tree in enumerate(elements):
            tree_id = tree.attrs.get("ID", f"BehaviorTree_{index}")
            if tree_id in trees and not self.foreign:
                # BehaviorTree.CPP writes a loaded tree with one BehaviorTree per instance;
                # we write each tree once, so in our files a second one is a mistake.
                self.problem(
                    tree.line, "a BehaviorTree ID no other BehaviorTree has", repr(tree_id)
                )
            trees.setdefault(tree_id, tree)
        return trees

    def _read_subtrees(self, trees: dict[str, Element], main_id: str | None) -> None:
        """Every tree but the main one into ``self.subtrees``: first their definitions and
        ports, then their nodes (an instance is read once all trees are known).
        """
        for tree_id, element in trees.items():
            if tree_id != main_id:
                self.subtrees[tree_id] = sub = self._subtree(tree_id, element)
                self._check_subtree_ref(sub, element)
                if tree_id not in self.models:  # written by BehaviorTree.CPP or Groot2
                    instances = instances_of(tree_id, list(trees.values()))
                    sub.inputs, sub.outputs = infer_subtree_ports(
                        element, instances, self._port_info
                    )
                    if any(autoremapped(i) for i in instances):
                        ports = {p.name for p in [*sub.inputs, *sub.outputs]}
                        used = names_used(tree_id, trees)
                        sub.shared_names = [n for n in used if n not in ports]
        for tree_id, element in trees.items():
            if tree_id != main_id:
                sub = self.subtrees[tree_id]
                sub.tree = self._root_node(element, sub.layout) or sub.tree

    def _check_subtree_ref(self, sub: SubtreeSpec, element: Element) -> None:
        """A plan holds each subtree version once (its file reader refuses a second)."""
        if any(other.ref == sub.ref for other in self.subtrees.values() if other is not sub):
            self.problem(
                element.line,
                "each subtree version once (a _uid and _version no other BehaviorTree has)",
                f"{sub.id!r} version {sub.version} a second time",
            )
        self.lines.subtrees.setdefault(sub.ref, element.line)

    def _port_info(self, element: Element, attr: str) -> tuple[Direction, ParamType] | None:
        """The direction and type of a port of an operation node, if it is known."""
        model_id = element.attrs.get("ID", "") if element.tag in _EXPLICIT else element.tag
        try:
            op, port = decode_id(model_id), decode_port(attr)
        except ValueError:
            return None
        manifest = self.manifests.get(op) if self.manifests is not None else None
        spec = manifest.port(port) if manifest is not None else None
        if spec is not None:
            return spec.direction, spec.type
        declared = self.models.get(model_id)
        if declared is None or port not in declared.ports:
            return None
        tag, ptype = declared.ports[port][:2]
        return (Direction.OUT if tag == "output_port" else Direction.IN), ptype

    def _root_node(self, tree: Element, layout: dict[str, NodeLayout]) -> NodeSpec | None:
        """The one node under a BehaviorTree; node ids are a namespace per tree."""
        self.ids = set()
        if len(tree.children) != 1:
            self.problem(tree.line, "one root node in the BehaviorTree", f"{len(tree.children)}")
        return self._node(tree.children[0], layout) if tree.children else None

    def _main_id(
        self,
        root: Element,
        data: Element | None,
        trees: dict[str, Element],
        own_trees: list[str],
    ) -> str | None:
        """The tree to run: the one named, else the file's only tree (not an included one),
        else its first. BehaviorTree.CPP refuses a file of several trees that names none
        unless its caller names one; what BehaviorTree.CPP itself writes (WriteTreeToXML: the
        main tree first, no main_tree_to_execute) is such a file, so the first is taken.
        """
        wanted = data.attrs.get("tree") if data is not None else None
        wanted = wanted or root.attrs.get("main_tree_to_execute")
        if wanted is None and len(own_trees) == 1 and own_trees[0]:
            wanted = own_trees[0]
        if wanted is None and trees:
            wanted = next(iter(trees))
        if wanted is None or wanted not in trees:
            got = repr(wanted) if wanted else "no BehaviorTree"
            self.problem(root.line, "the main tree named and present", got)
            return None
        return wanted

    def _node(self, element: Element, layout: dict[str, NodeLayout]) -> NodeSpec | None:
        node = self._kind_of(element)
        children = [self._node(child, layout) for child in element.children]
        if node is None:
            return None
        node.name = element.attrs.get("_name", element.attrs.get("name", ""))
        if self.foreign and node.name == (element.attrs.get("ID") or element.tag):
            node.name = ""  # BehaviorTree.CPP names an unnamed node after its type
        node.conditions = {
            condition: text
            for attr, condition in _CONDITIONS.items()
            if (text := element.attrs.get(attr, "")).strip()
        }
        node.id = element.attrs.get("_uid") or new_id()
        if node.id in self.ids:
            self.problem(element.line, "a _uid no other node has", repr(node.id))
        self.ids.add(node.id)
        self.lines.nodes.setdefault(node.id, element.line)
        where = self._layout(element)
        if where is not None:
            layout[node.id] = where
        if KIND_CATEGORY[node.kind] is Category.LEAF and children:
            self.problem(element.line, f"no children under a {element.tag}", f"{len(children)}")
        node.children = [c for c in children if c is not None]
        return node

    def _kind_of(self, element: Element) -> NodeSpec | None:
        tag = element.attrs.get("ID", "") if element.tag in _EXPLICIT else element.tag
        if tag == "SubTree":
            return self._instance(element)
        logic = LOGIC_BY_MODEL.get(tag)
        if logic is not None:
            return self._logic(element, logic)
        return self._operation(element, tag)

    def _ports(self, element: Element) -> dict[str, str]:
        ports: dict[str, str] = {}
        for key, value in element.attrs.items():
            if key in ("name", "ID") or key.startswith("_"):
                continue
            try:
                ports[decode_port(key)] = value
            except ValueError:
                self.problem(element.line, "a port name (p_ and an encoded id)", repr(key))
        return ports

    def _types(self, element: Element) -> dict[str, str]:
        text = element.attrs.get("_types", "")
        return dict(item.split("=", 1) for item in text.split(";") if "=" in item)

    def _binding(self, element: Element, port: str, text: str, ptype: ParamType) -> Binding | None:
        if text.startswith("{") and text.endswith("}") and len(text) >= 3:
            return Binding.reference(port if text == "{=}" else text[1:-1])
        overrides = self._types(element)
        if port in overrides:
            ptype = self._ptype(element, overrides[port])
        value = self._value(element, ptype, text, f"port {port!r}")
        return None if value is None else Binding.fixed(value, ptype)

    def _operation(self, element: Element, model_id: str) -> NodeSpec | None:
        try:
            op = decode_id(model_id)
        except ValueError:
            op = model_id
        declared = self.models.get(model_id)
        manifest = self.manifests.get(op) if self.manifests is not None else None
        known = manifest is not None if self.manifests is not None else declared is not None
        if not known or (declared is not None and declared.element not in ("Action", "Condition")):
            self.problem(
                element.line,
                "a node type this program knows (a mapped BehaviorTree.CPP node, Iterator, Enforce, SubTree or an operation)",
                f"unknown node type {model_id!r}",
            )
            return None
        node = NodeSpec(NodeKind.OPERATION, op=op)
        for port, text in self._ports(element).items():
            ptype = self._port_type(manifest, declared, port)
            if ptype is None:
                names = ", ".join(p.name for p in manifest.ports) if manifest else ""
                self.problem(element.line, f"a port of {op} ({names})", repr(port))
                continue
            binding = self._binding(element, port, text, ptype)
            if binding is not None:
                node.params[port] = binding
        return node

    def _port_type(
        self, manifest: OperationManifest | None, declared: Model | None, port: str
    ) -> ParamType | None:
        if manifest is not None:
            spec = manifest.port(port)
            return spec.type if spec is not None else None
        if declared is not None and port in declared.ports:
            return declared.ports[port][1]
        return None

    def _logic(self, element: Element, logic: LogicModel) -> NodeSpec:
        node = NodeSpec(logic.kind)
        for name, given in logic.implied.items():
            spec = kind_port(logic.kind, name)
            if spec is None or given != spec.default:  # a default stays unbound, as made
                node.params[name] = kind_setting(logic.kind, name, given)
        by_port = {m.port: (name, m) for name, m in logic.settings.items()}
        for port, text in self._ports(element).items():
            if port not in by_port:
                known = ", ".join(by_port) or "none"
                self.problem(element.line, f"a port of {logic.model} ({known})", repr(port))
                continue
            name, mapping = by_port[port]
            if not mapping.raw and text.startswith("{") and text.endswith("}"):
                node.params[name] = Binding.reference(text[1:-1])
                continue
            exact = element.attrs.get(f"_{name}")
            try:
                value = mapping.read(text) if exact is None else _setting_text(exact)
                node.params[name] = kind_setting(logic.kind, name, value)
            except ValueError:
                expected = "true or false" if port in _BOOL_PORTS else "a number"
                self.problem(
                    element.line, f"{port} {expected}", repr(text if exact is None else exact)
                )
        return node

    def _instance(self, element: Element) -> NodeSpec | None:
        tree_id = element.attrs.get("ID", "")
        sub = self.subtrees.get(tree_id)
        if sub is None:
            self.problem(element.line, "a SubTree whose BehaviorTree is in the file", repr(tree_id))
            return None
        if autoremapped(element) and tree_id in self.models:
            self.problem(
                element.line,
                '_autoremap="false" for a subtree whose model declares its ports and shared names',
                "_autoremap",
            )
        node = NodeSpec(NodeKind.SUBTREE, subtree=sub.ref)
        given = self._ports(element)
        model = self.models.get(tree_id)
        if model is not None and model.element == "SubTree" and not autoremapped(element):
            remaps = model_remaps(
                tree_id, model, given, lambda want, got: self.problem(element.line, want, got)
            )
            for port, key in remaps.items():
                if sub.port(port) is not None:
                    node.params[port] = Binding.reference(key)
        for port, text in given.items():
            spec = sub.port(port)
            if spec is None and port in sub.shared_names and text == "{" + port + "}":
                continue
            if text == UNUSED_OUTPUT and spec in sub.outputs:
                continue
            if spec is None:
                names = ", ".join(p.name for p in [*sub.inputs, *sub.outputs]) or "none"
                self.problem(element.line, f"a port of subtree {sub.name} ({names})", repr(port))
                continue
            binding = self._binding(element, port, text, spec.type)
            if binding is not None:
                node.params[port] = binding
        return node


_BOOL_PORTS = ("catch_on_halt", "then_skip")


def _setting_text(text: str) -> str | float:
    try:
        return float(text)
    except ValueError:
        return text


def _read(
    root: Element,
    source_name: str,
    manifests: Mapping[str, OperationManifest] | None,
    file: Path | None = None,
) -> XmlImport:
    reader = _Reader(manifests, file)
    plan = reader.plan(root)
    if reader.problems:
        raise XmlFileError(source_name, reader.problems)
    return XmlImport(plan, reader.lines, source_name)


def _syntax_error(file: str, exc: XmlSyntaxError) -> XmlFileError:
    return XmlFileError(file, [XmlProblem(exc.line, "well-formed UTF-8 XML", str(exc))])


def import_xml(
    text: str,
    source_name: str = "<string>",
    manifests: Mapping[str, OperationManifest] | None = None,
) -> PlanSpec:
    """A plan from BehaviorTree.CPP v4 XML (as :func:`engine.btcpp.export_xml` writes it, or
    written by BehaviorTree.CPP or Groot2).

    Args:
        text: the XML.
        source_name: the file as the user named it, for messages.
        manifests: operation id -> manifest; a node is an operation when its decoded id is
            here. None: any Action or Condition the file's TreeNodesModel declares.

    Raises:
        XmlFileError: every problem found, each with its line: unknown node types (all of
            them), unknown ports, values not of their port's form, malformed XML.
    """
    try:
        root = parse(text)
    except XmlSyntaxError as exc:
        raise _syntax_error(source_name, exc) from None
    return _read(root, source_name, manifests).plan


def read_xml(
    path: str | os.PathLike[str], manifests: Mapping[str, OperationManifest] | None = None
) -> XmlImport:
    """Read a BehaviorTree.CPP XML file (see :func:`import_xml`), with the line of each part.

    The file's size is checked before it is read (at most
    :data:`engine.btcpp.xmltree.MAX_FILE_BYTES`), and it is read in chunks.

    Raises:
        XmlFileError: the file cannot be read, is too large, is not UTF-8, or has problems.
    """
    file = os.fspath(path)
    try:
        with open(file, "rb") as handle:
            root = parse_file(handle)
    except OSError as exc:
        raise XmlFileError(
            file, [XmlProblem(0, "a readable file", exc.strerror or str(exc))]
        ) from None
    except XmlTooLarge as exc:
        expected = f"a tree file of at most {exc.limit // 1_000_000} MB ({exc.limit} bytes)"
        raise XmlFileError(file, [XmlProblem(0, expected, f"{exc.size} bytes")]) from None
    except XmlSyntaxError as exc:
        raise _syntax_error(file, exc) from None
    return _read(root, file, manifests, Path(file).resolve())


def load_xml(
    path: str | os.PathLike[str], manifests: Mapping[str, OperationManifest] | None = None
) -> PlanSpec:
    """Read a BehaviorTree.CPP XML file (see :func:`import_xml` and :func:`read_xml`).

    Raises:
        XmlFileError: the file cannot be read, is too large, is not UTF-8, or has problems.
    """
    return read_xml(path, manifests).plan
