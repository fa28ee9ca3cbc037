"""The plan's occupancy regions (spheres) as the camera panel and the 3D scene show them, and
how a region drawn by pointing is saved in the plan.

A plan holds a region in one of two places, both of which the occupancy operations read
through their ``region`` port: a fixed binding of a node's Region port, or a declared plan
parameter of type Region with an initial value (nodes then bind ``region`` to its name). A
drawn region goes to the selected node's Region port when the selected node has one, else to
a plan parameter (created, or replaced if one of that name exists). Both are one undo command
of the document.
"""

from __future__ import annotations

import copy

from engine.spec import Binding, NodeSpec, ParameterDecl, PlanSpec
from engine.types import ParamType, Region
from instructor_app.document.editing import PlanDocument

__all__ = ["plan_regions", "region_port", "save_region"]


def plan_regions(plan: PlanSpec) -> list[tuple[str, Region]]:
    """(name, region) of every region the plan holds: its Region parameters first, then
    the fixed Region bindings of nodes (named by the node's label).
    """
    found: list[tuple[str, Region]] = [
        (decl.name, decl.value)
        for decl in plan.parameters
        if decl.type is ParamType.REGION and isinstance(decl.value, Region)
    ]
    for _, node in plan.walk():
        for binding in node.params.values():
            if not binding.is_ref and isinstance(binding.value, Region):
                found.append((node.label, binding.value))
    return found


def region_port(node: NodeSpec | None) -> str | None:
    """The node's port that holds a region (an occupancy operation's ``region``), or None."""
    if node is None:
        return None
    for port, binding in node.params.items():
        if binding.type is ParamType.REGION or isinstance(binding.value, Region):
            return port
    return "region" if node.op is not None and node.op.startswith("occupancy.") else None


def save_region(
    document: PlanDocument, region: Region, node_id: str | None = None, name: str = "REGION"
) -> str:
    """Save a drawn region in the plan (one undo command); returns where it went.

    Args:
        document: the plan being edited.
        region: the sphere drawn.
        node_id: the selected node; its Region port takes the region if it has one.
        name: the plan parameter that takes it otherwise.
    """
    node = document.plan.find(node_id) if node_id else None
    port = region_port(node)
    if node is not None and port is not None:
        document.set_param(node.id, port, Binding.fixed(region, ParamType.REGION))
        return f"{node.label}: {port}"
    decl = next((copy.copy(p) for p in document.plan.parameters if p.name == name), None)
    if decl is None:
        decl = ParameterDecl(name, ParamType.REGION, region, "drawn by pointing")
    decl.type, decl.value = ParamType.REGION, region
    document.declare_parameter(decl)
    return f"plan parameter {name}"
