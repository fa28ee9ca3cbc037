"""The cheap paths into NodeGraphQt 0.6.44 (all version-dependent hacks live here).

Why: ``NodeGraph.create_node`` costs ~1.7-3 ms a node. Most of it is ``get_unique_name``,
which lists every node's name for each new node (quadratic: 500,000 ``name()`` calls for
1000 nodes); then ``node.update()`` pushes every property through its setter, which redraws
the node several times, and each creation and connection pushes a command on NodeGraphQt's
own undo stack. The canvas does not need any of that: node names need not be unique (the
plan's uuids identify nodes), the plan document owns undo, and an item is drawn once when
its content is set. The functions below do what ``NodeGraph.add_node`` and
``Port.connect_to`` do to NodeGraphQt's model and scene, minus those costs.

They rely on these NodeGraphQt internals (re-check them when upgrading NodeGraphQt):
``NodeModel._TEMP_*`` attributes, ``NodeGraphModel.nodes`` and
``set_node_common_properties``, ``PortModel.connected_ports`` (a defaultdict(list)),
``NodeViewer.establish_connection``, ``PortItem.connected_pipes`` and ``PipeItem.delete``,
``NodeGraph._wire_signals`` (disabled: the canvas connects the viewer's signals itself).
"""

from __future__ import annotations

from typing import Any

from NodeGraphQt import NodeGraph
from NodeGraphQt.constants import LayoutDirectionEnum, PipeLayoutEnum

from instructor_app.canvas.items import CHILD_PORT, PARENT_PORT, TreeNode

__all__ = ["TreeGraph", "add_node", "remove_node", "link", "unlink", "parent_pipe"]

_VERTICAL = LayoutDirectionEnum.VERTICAL.value
_TEMP_KEYS = (
    "_TEMP_property_widget_types",
    "_TEMP_property_attrs",
    "_TEMP_accept_connection_types",
    "_TEMP_reject_connection_types",
)


class TreeGraph(NodeGraph):
    """A NodeGraph for a top-down tree whose viewer's signals the canvas handles itself."""

    def __init__(self, viewer: Any, parent: Any = None) -> None:
        super().__init__(
            parent,
            viewer=viewer,
            layout_direction=_VERTICAL,
            pipe_style=PipeLayoutEnum.ANGLE.value,
        )

    def _wire_signals(self) -> None:
        # NodeGraph's slots would apply user gestures to its own model and undo stack;
        # the canvas turns them into document edits instead (CanvasView connects them).
        return

    def get_unique_name(self, name: str) -> str:
        # Plan nodes are identified by uuid; duplicate labels are fine (and the original
        # check is quadratic in the node count).
        return name


def add_node(graph: TreeGraph, node: TreeNode, node_id: str, pos: tuple[float, float]) -> None:
    """Put ``node`` into the graph and scene at ``pos`` under the plan's id (no undo)."""
    model = node.model
    temp = {key: model.__dict__.pop(key, None) for key in _TEMP_KEYS}
    if graph.model.get_node_common_properties(node.type_) is None:
        widget_types = temp["_TEMP_property_widget_types"] or {}
        attrs = {name: {"widget_type": kind} for name, kind in widget_types.items()}
        for name, extra in (temp["_TEMP_property_attrs"] or {}).items():
            attrs.setdefault(name, {}).update(extra)
        graph.model.set_node_common_properties({node.type_: attrs})
    node._graph = graph
    model._graph_model = graph.model
    model.id = node_id
    model.layout_direction = _VERTICAL
    model.selected = False
    view = node.view
    view.id = node_id
    view.type_ = node.type_
    view._properties["layout_direction"] = _VERTICAL  # the setter would redraw the node
    graph.model.nodes[node_id] = node
    view.setPos(pos[0], pos[1])
    graph.viewer().scene().addItem(view)
    model.pos = [float(pos[0]), float(pos[1])]
    model.width, model.height = view.width, view.height


def remove_node(graph: TreeGraph, node: TreeNode) -> None:
    """Take ``node`` (and the links on its ports) out of the graph and scene (no undo)."""
    for port in list(node.inputs().values()) + list(node.outputs().values()):
        for pipe in list(port.view.connected_pipes):
            _forget(pipe)
        port.model.connected_ports.clear()
    graph.model.nodes.pop(node.id, None)
    scene = node.view.scene()
    if scene is not None:
        scene.removeItem(node.view)


def link(graph: TreeGraph, parent: TreeNode, child: TreeNode) -> None:
    """Draw the parent -> child link (the child's previous parent link, if any, goes)."""
    unlink(graph, child)
    out_port = parent.outputs()[CHILD_PORT]
    in_port = child.inputs()[PARENT_PORT]
    out_port.model.connected_ports[child.id].append(PARENT_PORT)
    in_port.model.connected_ports[parent.id].append(CHILD_PORT)
    graph.viewer().establish_connection(in_port.view, out_port.view)


def unlink(graph: TreeGraph, child: TreeNode) -> None:
    """Remove the link from ``child`` to its parent (model and pipe), if there is one."""
    in_port = child.inputs()[PARENT_PORT]
    for parent_id in list(in_port.model.connected_ports):
        parent = graph.model.nodes.get(parent_id)
        if parent is not None:
            out_model = parent.outputs()[CHILD_PORT].model
            out_model.connected_ports.pop(child.id, None)
    in_port.model.connected_ports.clear()
    for pipe in list(in_port.view.connected_pipes):
        _forget(pipe)


def parent_pipe(child: TreeNode) -> Any | None:
    """The pipe item that links ``child`` to its parent, if drawn."""
    pipes = child.inputs()[PARENT_PORT].view.connected_pipes
    return pipes[0] if pipes else None


def _forget(pipe: Any) -> None:
    """Remove a pipe item from both its ports and the scene."""
    for port in (pipe.input_port, pipe.output_port):
        if port is not None and pipe in port.connected_pipes:
            port.remove_pipe(pipe)
    scene = pipe.scene()
    if scene is not None:
        scene.removeItem(pipe)
