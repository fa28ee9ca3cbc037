"""Issue 26 item 3: perception.detect_objects that recognises nothing while the arm hides
the table from the shoulder camera fails as ``occluded`` and says so.

Ground truth is read only here: to put the arm over the cup and leave the cup alone.
"""

from __future__ import annotations

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.perception import capability
from capabilities.sim.session import SimCellSession
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.executor import run_to_end
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from tests.capabilities.markers.test_markers_arm_hides_table import HIDES, OBSERVE, over_the_cup

pytestmark = pytest.mark.sim


def _detect(cell: SimCellSession) -> NodeSpec:
    registry = CapabilityRegistry([capability()], cell=cell)
    node = NodeSpec(NodeKind.OPERATION, name="look", op="perception.detect_objects")
    built = build_tree(PlanSpec(node), registry, clock=cell.clock)
    assert run_to_end(built, 100.0, timeout=60.0).reason == "finished"
    return built.root.children[0]


def test_nothing_recognised_under_the_arm_fails_as_occluded() -> None:
    with SimCellSession("cup_to_bin", seed=1) as cell:
        cell.sim.call(lambda client: cell.scene.remove(client, "waste_bin"))
        over_the_cup(cell, 0.05)  # the gripper around the cup
        look = _detect(cell)
        assert look.status is Status.FAILURE, look.message
        assert look.message.startswith(HIDES) and "no objects were recognised" in look.message
        assert look.error is ErrorType.OCCLUDED
        assert cell.sim.robot.move_joints(OBSERVE, speed=3.0, accel=6.0).wait(30)
        assert _detect(cell).status is Status.SUCCESS  # out of the view, the cup is found
