"""A paced simulated cell rests while nothing moves (issue 26): it stops stepping, simulated
time goes on with the wall clock, and a command, a call that changes the world or an actor's
step hook wakes it; gravity still acts on a body put in the air.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import pytest

from capabilities.bullet import pybullet
from capabilities.sim.session import SimCellSession


@pytest.fixture(scope="module")
def cell() -> Iterator[SimCellSession]:
    with SimCellSession("cup_to_bin", seed=0, speed=1.0) as session:
        yield session


def _until(condition: Callable[[], bool], timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.02)


def test_a_still_cell_rests_while_its_clock_goes_on(cell: SimCellSession) -> None:
    physics = cell.sim._physics
    _until(lambda: physics.resting)
    cell.sim.wait_sim(0.3)  # a waiter wakes it for as long as it waits ...
    _until(lambda: physics.resting)
    steps, clock = physics.steps, cell.sim.time()
    _until(lambda: cell.sim.time() >= clock + 0.3)  # ... at rest the clock goes on
    assert physics.steps == steps and physics.resting  # and no step was taken


def test_a_command_wakes_the_rest_and_the_arm_arrives(cell: SimCellSession) -> None:
    physics = cell.sim._physics
    _until(lambda: physics.resting)
    rests = physics.rests
    arm = cell.interfaces()["arm"]
    home = arm.joint_positions()
    target = (home[0] + 0.3, *home[1:])
    assert arm.move_joints(target).wait(30.0)
    assert max(abs(a - b) for a, b in zip(arm.joint_positions(), target, strict=True)) < 1e-3
    _until(lambda: physics.rests > rests)  # at rest again once still
    assert arm.move_joints(home).wait(30.0)


def test_gravity_acts_on_a_body_put_in_the_air_at_rest(cell: SimCellSession) -> None:
    physics = cell.sim._physics
    _until(lambda: physics.resting)
    body = cell.scene.objects["cup"].body_id

    def lift(client: int) -> float:
        position, orientation = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        raised = (position[0], position[1], position[2] + 0.2)
        pybullet.resetBasePositionAndOrientation(body, raised, orientation, physicsClientId=client)
        return float(position[2])

    rests = physics.rests
    resting_z = cell.sim.call(lift)
    _until(lambda: physics.rests > rests)  # it fell and came to rest again

    def height(client: int) -> float:
        return float(pybullet.getBasePositionAndOrientation(body, physicsClientId=client)[0][2])

    assert abs(cell.sim.peek(height) - resting_z) < 0.02


def test_an_actors_step_hook_keeps_the_world_stepping(cell: SimCellSession) -> None:
    physics = cell.sim._physics
    _until(lambda: physics.resting)
    seen: list[float] = []
    hook = seen.append
    cell.sim.add_step_hook(post=hook)
    try:
        _until(lambda: len(seen) > 60)  # stepping: the hook runs every step
        assert not physics.resting
    finally:
        cell.sim.remove_step_hook(post=hook)
    _until(lambda: physics.resting)
