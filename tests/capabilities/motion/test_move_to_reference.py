"""motion.move_to: a reference is used with every target it is given with, or refused.

Issue 26 item 2: a Pose target with a Pose reference (``BIN_POSE``) passed validation and
the reference was ignored at run time ("unreachable: pose (0,0,360)").
"""

from __future__ import annotations

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import TargetResolver
from engine.operations import OperationFailed
from engine.spec import Binding, NodeKind, NodeSpec, ParameterDecl, PlanSpec
from engine.types import JointConfig, ParamType, Pose, Waypoint, WaypointFrame
from engine.validation import ERROR, Problem, validate_plan
from tests.capabilities.motion.plans import DOWN, all_capabilities, op, seq

BIN = Pose((0.5, -0.2, 0.1), (0.0, 0.0, 0.0, 1.0))
ABOVE = Pose((0.0, 0.0, 0.36), DOWN)
HERE = Pose((0.3, 0.0, 0.4), DOWN)
JOINTS = Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig((0.0,) * 6))
WORLD = Waypoint("over exit", WaypointFrame.WORLD, Pose((0.5, 0.3, 0.1), DOWN))


def _resolver() -> TargetResolver:
    return TargetResolver(None, SymmetryTable())


def test_a_pose_target_is_taken_relative_to_a_pose_reference() -> None:
    resolved = _resolver().resolve(ABOVE, BIN, HERE)
    assert resolved.poses == (BIN.compose(ABOVE),)
    assert resolved.poses[0].position == pytest.approx((0.5, -0.2, 0.46))
    assert "relative to the reference" in resolved.describe


def test_a_pose_target_without_a_reference_stays_in_the_world() -> None:
    assert _resolver().resolve(ABOVE, "", HERE).poses == (ABOVE,)


@pytest.mark.parametrize("waypoint", [JOINTS, WORLD], ids=["joints", "world"])
@pytest.mark.parametrize("reference", [BIN, "cup"], ids=["pose", "text"])
def test_a_reference_with_a_world_or_joints_waypoint_fails_at_run_time(
    waypoint: Waypoint, reference: object
) -> None:
    with pytest.raises(OperationFailed, match=r"'reference' is set.*would be ignored"):
        _resolver().resolve(waypoint, reference, HERE)


def _problems(*nodes: NodeSpec, parameters: tuple[ParameterDecl, ...] = ()) -> list[Problem]:
    """The errors of a plan, but that this cell (none) has no arm."""
    plan = PlanSpec(seq(*nodes), "test", parameters=list(parameters))
    found = validate_plan(plan, CapabilityRegistry(all_capabilities()))
    return [p for p in found if p.severity == ERROR and "cannot run on" not in p.message]


def test_validation_accepts_a_pose_target_with_a_pose_reference() -> None:
    node = op("motion.move_to", "move to BIN_POSE", target=ABOVE, reference="$BIN_POSE")
    assert _problems(node, parameters=(ParameterDecl("BIN_POSE", ParamType.POSE, BIN),)) == []


@pytest.mark.parametrize("waypoint", [JOINTS, WORLD], ids=["joints", "world"])
def test_validation_names_the_node_and_port_of_an_ignored_reference(waypoint: Waypoint) -> None:
    node = op("motion.move_to", "step out of view", target=waypoint, reference="$BIN_POSE")
    problems = _problems(node, parameters=(ParameterDecl("BIN_POSE", ParamType.POSE, BIN),))
    assert len(problems) == 1, problems
    assert problems[0].node_id == node.id and problems[0].field == "reference"
    assert "step out of view" in problems[0].message
    assert "would be ignored" in problems[0].message


def test_validation_refuses_a_linear_move_to_joint_positions() -> None:
    node = op("motion.move_to", "step out of view", target=JOINTS, mode="linear")
    (problem,) = _problems(node)
    assert problem.field == "mode" and "joint positions" in problem.message


def test_an_empty_reference_text_is_no_reference() -> None:
    node = op("motion.move_to", "step out of view", target=JOINTS, reference="")
    assert _problems(node) == []
    fixed = NodeSpec(
        NodeKind.OPERATION,
        name="x",
        op="motion.move_to",
        params={"target": Binding.fixed(WORLD, ParamType.WAYPOINT)},
    )
    assert _problems(fixed) == []
