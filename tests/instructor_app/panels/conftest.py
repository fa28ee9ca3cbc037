"""Fixtures of the panel tests: a registry without a robot and a small plan document."""

from __future__ import annotations

import pytest

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.debug import capability as debug_capability
from capabilities.template import capability as template_capability
from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ParamType
from instructor_app.document import PlanDocument


@pytest.fixture
def registry() -> CapabilityRegistry:
    """Debug (always available) and template (needs a lamp the null cell lacks)."""
    return CapabilityRegistry([debug_capability(), template_capability()], cell=NullCell())


@pytest.fixture
def document(qapp: object) -> PlanDocument:
    """A plan: Sequence[query -> OBJ_POSE, pretend_move, wait], with a clean undo stack."""
    doc = PlanDocument()
    root = doc.add_node(NodeSpec(NodeKind.SEQUENCE, "Main", id="root"))
    doc.add_node(NodeSpec(NodeKind.OPERATION, "Find", id="query", op="debug.query"), root)
    doc.add_node(NodeSpec(NodeKind.OPERATION, "Go", id="move", op="debug.pretend_move"), root)
    doc.add_node(
        NodeSpec(
            NodeKind.WAIT,
            "Pause",
            id="wait",
            params={"seconds": Binding.fixed(1.0, ParamType.DURATION)},
        ),
        root,
    )
    doc.undo_stack.clear()
    return doc
