"""Our wire-bender tending plan (resources/examples/tending.costar.json) in short trials on
the ``tending`` scene: each fault is recovered by its library subtree with no operator (a
slipped grasp by Regrasp, a broken weld by DiscardToScrap, a moved rack by ReRegisterRack).
Ground truth is read here only, to set the faults up and to score."""

from __future__ import annotations

import math
from pathlib import Path

from capabilities.sim.bender import read_bender
from capabilities.sim.bender_spec import FaultModel, plan_parts
from capabilities.sim.objects import set_object_frame_pose
from capabilities.sim.session import SimCellSession
from capabilities.sim.tending_score import container_of
from capabilities.sim.tending_trial import OperatorModel, TendingTrial
from engine.types import Pose
from tests.capabilities.sim.test_bender import tending_scene
from tests.capabilities.sim.test_tending_paper import SPEED

PLAN = Path(__file__).resolve().parents[3] / "resources" / "examples" / "tending.costar.json"


def _where(session: SimCellSession, part: str) -> str:
    """GROUND TRUTH: 'caught' (in the rack's tote), 'scrapped' or ''."""
    scene = session.scene
    return session.sim.call(lambda c: container_of(c, scene, scene.truth_pose(c, part)))


def _seed_with(faults: list[tuple[bool, bool]], rates: FaultModel, scene: Path) -> int:
    """A seed whose parts have these (bad weld, bad grasp) faults."""
    spec = read_bender(scene)
    assert spec is not None
    for seed in range(500):
        if [(p.bad_weld, p.bad_grasp) for p in plan_parts(spec, seed, rates)] == faults:
            return seed
    raise AssertionError(f"no seed gives faults {faults}")


def test_a_slipped_grasp_is_regrasped_and_a_broken_weld_scrapped(tmp_path: Path) -> None:
    """Part 1 slips out of the first grasp: Regrasp takes it again and it ends on the rack.
    Part 2's weld comes apart when lifted: DiscardToScrap puts its pieces into the scrap bin.
    Part 3 is good and ends on the rack. The operator is never called."""
    scene = tending_scene(tmp_path, parts=3, interval=24.0)
    rates = FaultModel(bad_weld=0.4, bad_grasp=0.4, interval_spread=0.0)
    seed = _seed_with([(False, True), (True, False), (False, False)], rates, scene)
    with SimCellSession(scene, seed, speed=SPEED, faults=rates, start_actors=False) as session:
        trial = TendingTrial(session, PLAN, OperatorModel(present=False))
        counters = trial.run(tail=40.0, wall_timeout=400.0)
        bender = session.bender
        assert bender is not None
        kinds = [(e.kind, e.part) for e in bender.events()]
        assert ("slipped", "part_001") in kinds and ("weld_broke", "part_002") in kinds
        print(counters)
        assert _where(session, "part_001") == "caught"
        assert _where(session, "part_003") == "caught"
        assert counters.scrapped == 1 and counters.caught == 2 and counters.lost == 0
        assert trial.calls == []  # no operator
