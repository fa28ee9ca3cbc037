"""The occupancy operations' contract: waits with timeouts, fresh and cached frames, errors,
the table plane; on the simulated cell (shoulder camera 320x240) and on synthetic clouds.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.occupancy import capability
from capabilities.occupancy.region import estimate_table_z, read_region
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import run
from engine.build import build_tree
from engine.executor import run_to_end
from engine.operations import Job, OperationCall
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, RUNNING, SUCCESS
from engine.types import ParamType, Pose, Region
from tests.capabilities.occupancy.helpers import add_fixed_box, remove_body, run_op

SPOT = (0.6, -0.1, 0.05)
REGION = Region(SPOT, 0.1)
PARKED = (1.2, -2.2, 2.0, -1.4, -1.5708, 0.0)


@pytest.fixture(scope="module")
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty", seed=1, shoulder_size=(320, 240)) as cell:
        run(cell.sim.robot.move_joints(PARKED, speed=3.0, accel=6.0))
        yield cell


@pytest.fixture(scope="module")
def registry(session: SimCellSession) -> CapabilityRegistry:
    return CapabilityRegistry([capability()], cell=session)


def test_wait_until_occupied_times_out_on_an_empty_region(registry: CapabilityRegistry) -> None:
    outcome = run_op(registry, "occupancy.wait_until_occupied", region=REGION, timeout=0.5)
    assert outcome.status is FAILURE
    assert outcome.message.startswith("timed out after 0.5 s"), outcome
    assert "never occupied" in outcome.message and "0 points" in outcome.message


def test_waits_end_when_a_cube_comes_and_goes(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    body = add_fixed_box(session, Pose((SPOT[0], SPOT[1], 0.025)))
    outcome = run_op(registry, "occupancy.wait_until_occupied", region=REGION, timeout=2.0)
    assert outcome.ok and outcome.message.startswith("occupied"), outcome

    def take_away_later() -> None:
        session.sim.wait_sim(0.5)
        remove_body(session, body)

    remover = threading.Thread(target=take_away_later)
    remover.start()
    start = session.clock()
    outcome = run_op(registry, "occupancy.wait_until_empty", region=REGION, timeout=20.0)
    remover.join()
    assert outcome.ok, outcome
    assert session.clock() - start >= 0.5  # it waited for the removal, not less
    assert run_op(registry, "occupancy.is_empty", region=REGION, max_age=0.0).ok


def test_a_condition_answers_at_once_from_a_recent_frame(registry: CapabilityRegistry) -> None:
    assert run_op(registry, "occupancy.is_empty", region=REGION, max_age=0.0).ok
    operation = registry.create("occupancy.is_empty")
    call = OperationCall("n", "is_empty", {}, lambda *_: None, lambda *_: None, lambda: None,
                         registry.cell.clock)  # fmt: skip
    call.args = {"region": REGION, "camera": "shoulder", "min_points": 30.0,
                 "mask_robot": True, "max_age": 1000.0}  # fmt: skip
    job = operation.start(call)
    assert isinstance(job, Job)
    assert job.poll() is SUCCESS  # the first poll, in the same tick: no wait for a frame
    call.args["region"] = Region((0.35, -0.45, 0.05), 0.1)  # the suction tool's holster
    job = operation.start(call)
    assert job.poll() is FAILURE and "occupied" in job.message


def test_a_configured_table_height_is_used(session: SimCellSession) -> None:
    reg = CapabilityRegistry([capability()], cell=_Renamed(session),
                             settings={"occupancy": {"table_z": 0.3}})  # fmt: skip
    # The real table top (z = 0) is now an occupant: it is 30 cm below the configured one.
    outcome = run_op(reg, "occupancy.is_occupied", region=REGION, max_age=0.0)
    assert outcome.ok and "dropped 0 on the table" in outcome.message, outcome


class _Renamed:
    """The same cell under another identity (its own occupancy state)."""

    def __init__(self, session: SimCellSession) -> None:
        self.name = "sim"
        self._session = session

    def interfaces(self) -> dict[str, object]:
        return dict(self._session.interfaces())

    def clock(self) -> float:
        return self._session.clock()


def test_wait_until_occupied_in_a_tree(
    session: SimCellSession, registry: CapabilityRegistry
) -> None:
    node = NodeSpec(NodeKind.OPERATION, name="wait", op="occupancy.wait_until_occupied",
                    params={"region": Binding.fixed(REGION, ParamType.REGION),
                            "timeout": Binding.fixed(5.0, ParamType.DURATION)})  # fmt: skip
    tree = build_tree(PlanSpec(node, "test"), registry, clock=session.clock)
    body = add_fixed_box(session, Pose((SPOT[0] + 0.03, SPOT[1], 0.025)))
    try:
        result = run_to_end(tree, rate_hz=50.0, timeout=60.0)
    finally:
        remove_body(session, body)
    assert result.status is SUCCESS, [n.message for n in tree.iterate()]


# ------------------------------------------------------------------ synthetic clouds


def _plane(z: float, n: int, rng: np.random.Generator, half: float = 0.5) -> np.ndarray:
    xy = rng.uniform(-half, half, (n, 2)) + np.array([0.55, 0.0])
    return np.column_stack((xy, np.full(n, z) + rng.normal(0, 0.001, n)))


def test_the_table_is_the_highest_large_plane_not_the_floor() -> None:
    rng = np.random.default_rng(0)
    cloud = np.vstack((_plane(-0.75, 30000, rng, 1.5), _plane(0.02, 20000, rng),
                       rng.uniform(-0.5, 0.6, (5000, 3))))  # fmt: skip
    found = estimate_table_z(cloud)
    assert found is not None and abs(found - 0.02) < 0.002
    assert estimate_table_z(rng.uniform(-1, 1, (5000, 3))) is None  # no plane at all


def test_a_region_through_the_table_reads_only_what_stands_on_it() -> None:
    rng = np.random.default_rng(1)
    table = _plane(0.0, 40000, rng)
    region = Region((0.55, 0.0, 0.0), 0.1)
    reading = read_region(table, region, 0.0, 0.008)
    assert reading.points == 0 and reading.table == reading.in_region > 100
    cube = rng.uniform(-0.025, 0.025, (200, 3)) + np.array([0.55, 0.0, 0.025])
    reading = read_region(np.vstack((table, cube)), region, 0.0, 0.008)
    assert 100 < reading.points <= 200
    masked = read_region(np.vstack((table, cube)), region, 0.0, 0.008,
                         lambda p: p[:, 2] > 0.0)  # fmt: skip
    assert masked.points == 0 and masked.robot == reading.points


def test_is_occupied_is_not_running_forever_when_the_camera_fails() -> None:
    class Broken:
        name, on_wrist = "shoulder", False

        def capture(self, max_width: int | None = None) -> object:
            raise RuntimeError("no signal")

    class Cell:
        name = "broken"

        def __init__(self) -> None:
            from capabilities.jobs import WorkerPool

            self.pool = WorkerPool(1)

        def interfaces(self) -> dict[str, object]:
            return {"workers": self.pool, "rgbd:shoulder": Broken()}

        def clock(self) -> float:
            return 0.0

    cell = Cell()
    try:
        reg = CapabilityRegistry([capability()], cell=cell)
        outcome = run_op(reg, "occupancy.is_occupied", region=REGION, mask_robot=False)
        assert outcome.status is FAILURE and "no signal" in outcome.message, outcome
        assert outcome.status is not RUNNING
    finally:
        cell.pool.close()
