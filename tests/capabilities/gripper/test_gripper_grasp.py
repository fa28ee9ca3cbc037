"""gripper: open/close and the holding sensor; a cup is grasped, carried and put down."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import down_at
from engine.status import Status
from tests.capabilities.motion.plans import op, run_plan, seq

pytestmark = pytest.mark.sim

GRASP_Z = 0.06  # m: TCP height that grips the 100 mm cup around its middle
CARRY_Z = 0.22
PLACE = (0.45, 0.30)  # free table space in the cup_to_bin scene with seed 0


@pytest.fixture
def session() -> Iterator[SimCellSession]:
    with SimCellSession("cup_to_bin", seed=0) as cell:
        yield cell


def test_closing_on_nothing_is_closed_but_not_holding(session: SimCellSession) -> None:
    run = run_plan(
        session,
        seq(op("gripper.close"), op("gripper.is_closed"), op("gripper.is_holding", "holding")),
    )
    assert run.status is Status.FAILURE and run.messages()["holding"] == "false"
    run = run_plan(session, seq(op("gripper.open"), op("gripper.is_closed", "closed")))
    assert run.status is Status.FAILURE and run.messages()["closed"] == "false"


def test_the_cup_is_carried_and_released_where_asked(session: SimCellSession) -> None:
    x, y, _ = session.truth_pose("cup").position  # the test knows; the plan is given poses
    pick = seq(
        op("gripper.open"),
        op("motion.move_to", "above cup", target=down_at(x, y, CARRY_Z)),
        op("motion.move_to", "down", target=down_at(x, y, GRASP_Z), mode="linear"),
        op("gripper.close"),
        op("gripper.is_holding"),
        op("motion.move_relative", "lift", dz=CARRY_Z - GRASP_Z),
    )
    run = run_plan(session, pick)
    assert run.status is Status.SUCCESS, run.failure()
    assert session.truth_pose("cup").position[2] > 0.1  # off the table, in the gripper

    place = seq(
        op("motion.move_to", "over place", target=down_at(*PLACE, CARRY_Z, yaw=0.8)),
        op("gripper.is_holding", "still holding"),
        op(
            "motion.move_to",
            "lower",
            target=down_at(*PLACE, GRASP_Z + 0.003, yaw=0.8),
            mode="linear",
        ),
        op("gripper.open"),
        op("motion.move_relative", "clear", dz=0.1),
        op("gripper.is_holding", "holding after release"),
    )
    run = run_plan(session, place)
    assert run.status is Status.FAILURE
    assert run.messages()["holding after release"] == "false", run.failure()
    assert run.statuses()["still holding"] is Status.SUCCESS
    assert run.statuses()["clear"] is Status.SUCCESS
    session.sim.wait_sim(0.5)
    cup = session.truth_pose("cup")
    assert math.dist(cup.position[:2], PLACE) < 0.02
    assert abs(cup.position[2]) < 0.005  # standing on the table
