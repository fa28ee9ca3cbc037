"""Document -> graph: keeps the NodeGraphQt scene a mirror of the plan.

A rebuild happens only on ``plan_reset``; every other document signal touches the nodes it
names and then re-places the items whose position changed (the tidy layout of a 1000-node
tree takes a few milliseconds in pure Python; moving items is what costs, so only moved
items are touched).

Positions: a node with a position in the plan's layout block stays there (manual placement);
any other node goes where the tidy layout puts it, shifted along with its parent when the
parent was placed by hand. A layout entry at exactly (0, 0) counts as "no position" because
``PlanDocument.set_collapsed`` creates entries at (0, 0) that only carry the collapsed flag.
"""

from __future__ import annotations

from collections.abc import Callable

from engine.operations import OperationKind
from engine.spec import Category, NodeLayout, NodeSpec
from instructor_app.canvas import ngqt_fast
from instructor_app.canvas.items import TreeNode
from instructor_app.canvas.layout import LayoutMetrics, descendant_count, tidy_layout
from instructor_app.canvas.style import NodeLook, look_of
from instructor_app.document.editing import PlanDocument

__all__ = ["GraphMirror", "has_position", "METRICS"]

METRICS = LayoutMetrics(node_width=180.0, level_height=150.0, gap=30.0)

OpKindLookup = Callable[[str], OperationKind | None]


def has_position(layout: NodeLayout | None) -> bool:
    """Whether a layout entry places its node by hand (see the module docstring)."""
    return layout is not None and (layout.x != 0.0 or layout.y != 0.0)


class GraphMirror:
    """Creates, updates and places the graph's nodes from the document.

    Attributes:
        nodes: plan node id -> its NodeGraphQt node.
    """

    def __init__(self, document: PlanDocument, graph: ngqt_fast.TreeGraph) -> None:
        self.document = document
        self.graph = graph
        self.nodes: dict[str, TreeNode] = {}
        self.op_kind: OpKindLookup = lambda op: None
        self.kinds_known = False  # set_operation_kinds was called: a missing op is unknown

    # ------------------------------------------------------------------ document signals

    def rebuild(self) -> None:
        """Drop every node and build the whole plan again (plan_reset)."""
        for node in list(self.nodes.values()):
            ngqt_fast.remove_node(self.graph, node)
        self.nodes.clear()
        root = self.document.plan.tree
        if root is not None:
            self._add_subtree(root, None)

    def inserted(self, parent_id: str, index: int, node_id: str) -> None:
        self._add_subtree(self.document.node(node_id), parent_id or None)

    def removed(self, parent_id: str, index: int, node_ids: list[str]) -> None:
        for node_id in node_ids:
            node = self.nodes.pop(node_id, None)
            if node is not None:
                ngqt_fast.remove_node(self.graph, node)
        self.relayout()

    def moved(
        self, node_id: str, old_parent: str, old_index: int, new_parent: str, new_index: int
    ) -> None:
        self.restore_link(node_id)
        self.relayout()

    def changed(self, node_id: str) -> None:
        node = self.nodes.get(node_id)
        if node is not None:
            node.item.set_look(self._look(self.document.node(node_id)))

    def restyle(self) -> None:
        """Recompute every node's look (after the operation kinds became known)."""
        for _, spec in self.document.plan.walk():
            node = self.nodes.get(spec.id)
            if node is not None:
                node.item.set_look(self._look(spec))

    def restore_link(self, node_id: str) -> None:
        """Make the drawn parent link of ``node_id`` match the plan again."""
        node = self.nodes.get(node_id)
        if node is None:
            return
        parent_id, _, _ = self.document.locate(node_id)
        if parent_id is None:
            ngqt_fast.unlink(self.graph, node)
        else:
            ngqt_fast.link(self.graph, self.nodes[parent_id], node)
        self.graph.viewer().mark_links_dirty()

    # ------------------------------------------------------------------ placing

    def auto_positions(self) -> dict[str, tuple[float, float]]:
        """Where the tidy layout puts every visible node."""
        plan = self.document.plan
        collapsed = {key for key, value in plan.layout.items() if value.collapsed}
        return tidy_layout(plan.tree, collapsed, METRICS)

    def relayout(self) -> None:
        """Place, show or hide every item as the plan and its layout block say."""
        plan = self.document.plan
        if plan.tree is None:
            return
        auto = self.auto_positions()
        stack: list[tuple[NodeSpec, bool, float, float, int]] = [(plan.tree, True, 0.0, 0.0, 0)]
        while stack:
            spec, visible, dx, dy, badge = stack.pop()
            layout = plan.layout.get(spec.id)
            collapsed = layout is not None and layout.collapsed
            item = self.nodes[spec.id].item
            item.set_badges(badge, descendant_count(spec) if collapsed else 0)
            if visible:
                ax, ay = auto[spec.id]
                if layout is not None and has_position(layout):
                    x, y = layout.x, layout.y
                else:
                    x, y = ax + dx, ay + dy
                dx, dy = x - ax, y - ay
                if item.pos().x() != x or item.pos().y() != y:
                    item.setPos(x, y)
            self._set_visible(spec.id, visible)
            numbered = spec.category is Category.COMPOSITE
            for index, child in enumerate(spec.children):
                stack.append(
                    (child, visible and not collapsed, dx, dy, index + 1 if numbered else 0)
                )
        self.graph.viewer().mark_links_dirty()

    def _set_visible(self, node_id: str, visible: bool) -> None:
        node = self.nodes[node_id]
        item = node.item
        if item.isVisible() is visible:
            return
        if not visible and item.isSelected():
            item.setSelected(False)
        item.setVisible(visible)
        pipe = ngqt_fast.parent_pipe(node)
        if pipe is not None:
            pipe.draw_path(pipe.input_port, pipe.output_port)  # shows or hides it

    # ------------------------------------------------------------------ creating

    def _look(self, spec: NodeSpec) -> NodeLook:
        kind = self.op_kind(spec.op) if spec.op else None
        return look_of(spec, kind, unknown=bool(spec.op) and self.kinds_known and kind is None)

    def _add_subtree(self, root: NodeSpec, parent_id: str | None) -> None:
        """Create the items of ``root`` and below, place them, then draw their links (a
        link drawn before its ends are placed would be drawn again when they move).
        """
        created: list[tuple[TreeNode, str | None]] = []
        overview = self.graph.viewer().overview_mode
        stack: list[tuple[NodeSpec, str | None]] = [(root, parent_id)]
        while stack:
            spec, parent = stack.pop()
            node = TreeNode(leaf=spec.category is Category.LEAF)
            node.item.set_look(self._look(spec))
            if overview:  # zoomed out, ports are hidden (see CanvasViewer)
                for port in node.item.inputs + node.item.outputs:
                    port.setVisible(False)
            ngqt_fast.add_node(self.graph, node, spec.id, (0.0, 0.0))
            self.nodes[spec.id] = node
            created.append((node, parent))
            stack.extend((child, spec.id) for child in spec.children)
        self.relayout()
        for node, parent in created:
            if parent is not None:
                ngqt_fast.link(self.graph, self.nodes[parent], node)
