"""Occupancy on the simulated cell's rendered point clouds (320x240 shoulder camera).

Rates are measured over many random placements and asserted against the issue's
thresholds: a 5 cm cube in a 10 cm (radius) sphere is seen in >= 99% of frames, an empty
sphere (touching the table) reads occupied in < 1%, and the robot passing through a sphere
is not counted with masking on and is counted with it off.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.occupancy import capability
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import down_at, run
from engine.types import Pose, Region
from tests.capabilities.occupancy.helpers import add_fixed_box, remove_body, run_op

RADIUS = 0.10
CUBE = 0.05
HALF_DIAGONAL = CUBE * math.sqrt(3) / 2
# Sphere centres 0.3 m apart over the table, 6 cm up: every sphere reaches into the table.
CENTRES = [(x, y, 0.06) for x in (0.42, 0.72) for y in (-0.25, 0.0, 0.25)]
# The arm folded up and turned away over the robot's left, out of the way of the table.
PARKED = (1.2, -2.2, 2.0, -1.4, -1.5708, 0.0)


@pytest.fixture(scope="module")
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty", seed=0, shoulder_size=(320, 240)) as cell:
        yield cell


@pytest.fixture(scope="module")
def registry(session: SimCellSession) -> CapabilityRegistry:
    return CapabilityRegistry([capability()], cell=session)


def _random_rotation(rng: np.random.Generator) -> tuple[float, float, float, float]:
    q = rng.normal(size=4)
    return tuple(q / np.linalg.norm(q))  # type: ignore[return-value]  # numpy cannot tell the length is 4


def _placement(rng: np.random.Generator, centre: tuple[float, float, float]) -> Pose:
    """A cube wholly inside the sphere: half resting on the table, half anywhere above it."""
    reach = RADIUS - HALF_DIAGONAL
    if rng.random() < 0.5:
        r, a = reach * 0.8 * math.sqrt(rng.random()), rng.uniform(0, 2 * math.pi)
        yaw = rng.uniform(0, 2 * math.pi)
        return Pose((centre[0] + r * math.cos(a), centre[1] + r * math.sin(a), CUBE / 2),
                    (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))  # fmt: skip
    while True:
        offset = rng.uniform(-reach, reach, 3)
        point = np.add(centre, offset)
        if np.linalg.norm(offset) <= reach and point[2] >= HALF_DIAGONAL + 0.002:
            return Pose.of(point, _random_rotation(rng))


def _occupied_after(registry: CapabilityRegistry, session: SimCellSession, since: float,
                    region: Region, **args: object) -> bool:  # fmt: skip
    """is_occupied on a frame taken after ``since`` (cell time)."""
    outcome = run_op(registry, "occupancy.is_occupied", region=region,
                     max_age=max(0.0, session.clock() - since), **args)  # fmt: skip
    assert "camera" not in outcome.message, outcome
    return outcome.ok


def test_cube_is_seen_and_empty_spheres_stay_empty(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    run(session.sim.robot.move_joints(PARKED, speed=3.0, accel=6.0))
    rng = np.random.default_rng(2024)
    seen = missed = false_alarms = empty_checks = 0
    for _ in range(36):
        full = rng.random(len(CENTRES)) < 0.5
        bodies = [
            add_fixed_box(session, _placement(rng, c))
            for c, f in zip(CENTRES, full, strict=True)
            if f
        ]
        since = session.clock()
        for centre, has_cube in zip(CENTRES, full, strict=True):
            occupied = _occupied_after(registry, session, since, Region(centre, RADIUS))
            if has_cube:
                seen, missed = seen + occupied, missed + (not occupied)
            else:
                empty_checks, false_alarms = empty_checks + 1, false_alarms + occupied
        for body in bodies:
            remove_body(session, body)
    detection_rate = seen / (seen + missed)
    false_rate = false_alarms / empty_checks
    print(f"cube seen in {seen}/{seen + missed} = {detection_rate:.3f}; "
          f"empty read occupied in {false_alarms}/{empty_checks} = {false_rate:.3f}")  # fmt: skip
    assert seen + missed >= 90 and empty_checks >= 90
    assert detection_rate >= 0.99
    assert false_rate < 0.01


def _gripper_in_sphere(session: SimCellSession, centre: tuple[float, float, float]) -> bool:
    """GROUND TRUTH: the gripper body (from the flange 10 cm down) is in the sphere."""
    flange = session.ground_truth.flange_pose().position
    return math.dist(flange, centre) < RADIUS - 0.02


def test_robot_in_a_sphere_counts_only_without_the_mask(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    centre = (0.55, 0.05, 0.2)
    region = Region(centre, RADIUS)
    rng = np.random.default_rng(5)
    masked = unmasked = frames = 0
    for _ in range(8):
        # The TCP below the centre: the gripper body and the wrist fill the sphere.
        target = np.add(centre, (0.0, 0.0, -0.1)) + rng.uniform(-0.03, 0.03, 3)
        run(session.sim.robot.move_pose_joint_space(down_at(*target, rng.uniform(-1, 1))))
        since = session.clock()
        assert _gripper_in_sphere(session, centre)
        masked += _occupied_after(registry, session, since, region)
        unmasked += _occupied_after(registry, session, since, region, mask_robot=False)
        frames += 1
    # And while the arm sweeps through the sphere: in real time, so that frames are taken all
    # along the sweep whatever the machine's load (as fast as possible, the sweep can be over
    # between two frames).
    moving = 0
    with SimCellSession("empty", seed=0, speed=1.0, shoulder_size=(320, 240)) as live:
        live_registry = CapabilityRegistry(cell=live)
        run(live.sim.robot.move_pose_joint_space(down_at(0.55, -0.1, 0.1)))
        sweep = live.sim.robot.move_linear(down_at(0.55, 0.2, 0.1), speed=0.1)
        while not sweep.done():
            masked += _occupied_after(live_registry, live, live.clock(), region)
            moving += 1
        run(sweep)
    print(f"robot in the sphere: occupied with the mask in {masked}/{frames + moving} frames, "
          f"without it in {unmasked}/{frames} frames")  # fmt: skip
    assert moving >= 5
    assert masked == 0
    assert unmasked == frames


def test_a_cube_beside_the_gripper_still_counts_with_the_mask(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    centre = (0.55, 0.0, 0.08)
    run(session.sim.robot.move_pose_joint_space(down_at(0.55, 0.0, 0.12)))
    body = add_fixed_box(session, Pose((0.55, 0.075, CUBE / 2)))
    try:
        since = session.clock()
        outcome = run_op(registry, "occupancy.count_points", region=Region(centre, RADIUS))
        assert outcome.ok, outcome
        assert outcome.outputs["count"] >= 30, outcome
        assert session.clock() >= since
        assert _occupied_after(registry, session, since, Region(centre, RADIUS), camera="wrist")
    finally:
        remove_body(session, body)


def test_the_wrist_camera_masks_its_own_gripper(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    run(session.sim.robot.move_pose_joint_space(down_at(0.55, 0.0, 0.12)))
    region = Region((0.55, 0.0, 0.12), RADIUS)  # round the fingers, which fill the wrist view
    since = session.clock()
    assert not _occupied_after(registry, session, since, region, camera="wrist")
    assert _occupied_after(registry, session, since, region, camera="wrist", mask_robot=False)
