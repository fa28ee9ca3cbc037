"""gripper.grasp on the simulated cell: "grasp CUP at CUP_POSE" with the cup's pose from its
markers in a rendered image, and a plate taken with the suction tool at its pose from
model-based recognition. Ground truth is read only here, to check the object is lifted.
"""

from __future__ import annotations

import math

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.sim.session import SimCellSession
from engine.error_types import ErrorType
from engine.spec import Binding, NodeSpec
from engine.status import Status
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Waypoint, WaypointFrame
from tests.capabilities.motion.plans import build, op, run_plan, seq, sim_steps

pytestmark = pytest.mark.sim

OBSERVE = Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig((1.2, -1.9, 2.0, -1.6, -1.57, 0.0)))  # fmt: skip


def _object(name: str) -> Binding:
    return Binding.fixed(ObjectModel(name), ParamType.OBJECT)


def _look_and_grasp(finder: str, detect: str, model: str, **grasp: object) -> NodeSpec:
    return seq(
        op("motion.move_to", "step out of view", target=OBSERVE),
        op(f"{finder}.{detect}", "detect", camera="shoulder"),
        op(f"{finder}.object_pose", "pose", object=_object(model), pose=Binding.reference("POSE")),
        op("gripper.grasp", "grasp at POSE", object=_object(model), pose="$POSE", **grasp),
    )


@pytest.mark.parametrize(("seed", "grasp"), [(0, "first"), (4, "first"), (7, "rim")])
def test_grasp_cup_at_cup_pose_lifts_the_cup(seed: int, grasp: str) -> None:
    with SimCellSession("cup_to_bin", seed=seed) as session:
        before = session.truth_pose("cup")
        plan = _look_and_grasp("markers", "detect_markers", "cup", grasp=grasp)
        run = run_plan(session, plan, CapabilityRegistry(cell=session), timeout=60)
        assert run.status is Status.SUCCESS, run.failure()
        assert session.sim.gripper.is_holding()
        lifted = session.truth_pose("cup")
        assert lifted.position[2] - before.position[2] > 0.12  # lifted back to the approach
        assert math.dist(lifted.position[:2], before.position[:2]) < 0.02
        tcp_height = 0.06 if grasp == "first" else 0.085  # where the fingers hold the cup
        tcp = session.sim.robot.tcp_pose()
        assert tcp.position[2] - lifted.position[2] == pytest.approx(tcp_height, abs=0.01)


def test_grasp_plate_with_the_suction_tool_at_its_recognised_pose() -> None:
    with SimCellSession("kitting", seed=0) as session:
        before = session.truth_pose("plate_4_holes")
        plan = seq(
            op("tool.unholster"),
            _look_and_grasp("perception", "detect_objects", "plate_4_holes"),
        )
        run = run_plan(session, plan, CapabilityRegistry(cell=session), timeout=120)
        assert run.status is Status.SUCCESS, run.failure()
        assert session.sim.suction.has_part()
        lifted = session.truth_pose("plate_4_holes")
        assert lifted.position[2] - before.position[2] > 0.08
        assert math.dist(lifted.position[:2], before.position[:2]) < 0.02


def test_a_gripper_grasp_with_the_suction_tool_in_hand_says_what_to_do() -> None:
    with SimCellSession("cup_to_bin", seed=0) as session:
        plan = seq(
            op("tool.unholster"),
            op("gripper.grasp", "grasp", object=_object("cup"), pose=Pose((0.5, 0.0, 0.0))),
        )
        run = run_plan(session, plan, CapabilityRegistry(cell=session), timeout=60)
        assert run.status is Status.FAILURE
        assert "put it back first (tool.holster)" in run.messages()["grasp"]


def test_figure3_literal_move_to_cup_pose_with_a_grasp_reference_then_close() -> None:
    """The paper's "move to CUP_POSE", then "grasp" (close): the grasp reference makes the
    move go through the grasp's approach to where the fingers close around the cup.
    """
    with SimCellSession("cup_to_bin", seed=2) as session:
        before = session.truth_pose("cup")
        plan = seq(
            op("motion.move_to", "step out of view", target=OBSERVE),
            op("markers.detect_markers", "detect", camera="shoulder"),
            op("markers.object_pose", "pose", object=_object("cup"), pose=Binding.reference("P")),
            op("gripper.open"),
            op("motion.move_to", "move to CUP_POSE", target="$P", reference="cup/top"),
            op("gripper.close", "grasp"),
            op("gripper.is_holding", "holding"),
            op("motion.move_relative", "lift", dz=0.1),
            op("motion.move_to", "bad reference", target="$P", reference="cup/side"),
        )
        run = run_plan(session, plan, CapabilityRegistry(cell=session), timeout=60)
        assert run.statuses()["lift"] is Status.SUCCESS, run.failure()
        assert session.truth_pose("cup").position[2] - before.position[2] > 0.08
        assert run.status is Status.FAILURE
        message = run.messages()["bad reference"]
        assert "grasp reference 'cup/side'" in message and "(it has top, rim)" in message


def test_halting_a_grasp_stops_the_arm() -> None:
    with SimCellSession("cup_to_bin", seed=0) as session:
        arm = session.sim.robot
        cup = Pose((0.55, -0.1, 0.0))  # a pose as a query would give it; the cup need not be there
        tree = build(session, op("gripper.grasp", object=_object("cup"), pose=cup))
        assert tree.tick() is Status.RUNNING
        moving = False
        for _ in sim_steps(session, 0.05, 3.0):
            assert tree.tick() is Status.RUNNING
            if arm.is_moving():
                moving = True
                break
        assert moving
        tree.reset()
        session.sim.wait_sim(0.3)
        assert max(abs(v) for v in arm.joint_velocities()) < 0.01


def test_a_grasp_that_closes_on_nothing_fails_with_grasp_failed() -> None:
    with SimCellSession("cup_to_bin", seed=0) as session:
        cup = session.truth_pose("cup")
        empty = Pose((cup.position[0], cup.position[1] + 0.15, cup.position[2]), cup.orientation)
        run = run_plan(
            session,
            seq(op("gripper.grasp", "grasp", object=_object("cup"), pose=empty)),
            CapabilityRegistry(cell=session),
        )
        assert run.status is Status.FAILURE
        assert "the cup is not held" in run.messages()["grasp"]
        grasp = next(n for n in run.tree.root.iterate() if n.name == "grasp")
        assert grasp.error is ErrorType.GRASP_FAILED  # what a Catch with a re-grasp takes
