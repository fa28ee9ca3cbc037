"""freedrive: guide the arm by hand, record waypoints, go back to them."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import angle_between, distance, down_at
from engine.status import Status
from engine.types import JointConfig, Waypoint, WaypointFrame
from tests.capabilities.motion.plans import op, run_plan, seq

pytestmark = pytest.mark.sim

MM = 1e-3
HALF_DEG = math.radians(0.5)


@pytest.fixture
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty") as cell:
        yield cell


def test_record_a_waypoint_after_hand_guiding_and_return_to_it(session: SimCellSession) -> None:
    arm = session.sim.robot
    run = run_plan(session, op("freedrive.start"))
    assert run.status is Status.SUCCESS and arm.freedrive_active()
    refused = run_plan(session, op("motion.go_home", "home"))
    assert refused.status is Status.FAILURE and "freedrive" in refused.messages()["home"]

    drag = arm.freedrive_drag_to(down_at(0.45, -0.2, 0.2, yaw=0.3))  # the worker's hand
    assert drag.wait(60) and drag.ok, drag.message
    taught = arm.tcp_pose()

    plan = seq(
        op("freedrive.record_waypoint", "pose", name="taught", waypoint="$WP"),
        op("freedrive.record_waypoint", "joints", name="taught_q", frame="joints", waypoint="$WQ"),
        op("freedrive.stop"),
        op("motion.go_home"),
        op("motion.move_to", "to pose", target="$WP"),
        op("motion.current_pose", "p", pose="$P"),
        op("motion.go_home", "home again"),
        op("motion.move_to", "to joints", target="$WQ"),
        op("motion.current_pose", "p2", pose="$P2"),
    )
    run = run_plan(session, plan)
    assert run.status is Status.SUCCESS, run.failure()
    assert not arm.freedrive_active()
    wp, wq = run.value("WP"), run.value("WQ")
    assert isinstance(wp, Waypoint) and wp.name == "taught" and wp.frame is WaypointFrame.WORLD
    assert wp.pose is not None and distance(wp.pose, taught) < MM
    assert wq.frame is WaypointFrame.JOINTS and isinstance(wq.joints, JointConfig)
    for key in ("P", "P2"):
        assert (
            distance(run.value(key), taught) < MM
            and angle_between(run.value(key), taught) < HALF_DEG
        )


def test_record_needs_a_name(session: SimCellSession) -> None:
    run = run_plan(session, op("freedrive.record_waypoint", "rec", name="  ", waypoint="$W"))
    assert run.status is Status.FAILURE and "name" in run.messages()["rec"]
