"""The paper's wire-bender tending plan (resources/examples/tending_paper.costar.json) in a
short trial on the ``tending`` scene: a bad weld stops the robot until the operator presses
Continue, while the bender goes on; the next, good part ends on the rack. Ground truth is
read here only.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from capabilities.sim.bender import read_bender
from capabilities.sim.bender_spec import FaultModel, plan_parts
from capabilities.sim.session import SimCellSession
from capabilities.sim.tending_score import TrialCounters, container_of
from capabilities.sim.tending_trial import OperatorModel, TendingTrial, trial_session
from engine.events import StatusChanged
from tests.capabilities.sim.test_bender import tending_scene

PLAN = Path(__file__).resolve().parents[3] / "resources" / "examples" / "tending_paper.costar.json"


def _where(session: SimCellSession, part: str) -> str:
    """GROUND TRUTH: 'caught' (in the rack's tote), 'scrapped' or ''."""
    scene = session.scene
    return session.sim.call(lambda c: container_of(c, scene, scene.truth_pose(c, part)))


def _seed_with(bad_welds: list[bool], faults: FaultModel, scene: Path) -> int:
    """A seed whose parts have these welds (the plan is drawn from the seed)."""
    spec = read_bender(scene)
    assert spec is not None
    for seed in range(200):
        if [p.bad_weld for p in plan_parts(spec, seed, faults)] == bad_welds:
            return seed
    raise AssertionError(f"no seed gives welds {bad_welds}")


def test_a_bad_weld_stops_the_robot_until_the_operator_resets_it(tmp_path: Path) -> None:
    """Part 1's weld comes apart when lifted: the robot drops it, steps back and waits for
    the operator; after Continue it catches part 2 and puts it on the rack.
    """
    scene = tending_scene(tmp_path, parts=2, interval=18.0)
    faults = FaultModel(bad_weld=0.5, bad_grasp=0.0, interval_spread=0.0)
    seed = _seed_with([True, False], faults, scene)
    with trial_session(scene, seed, faults=faults) as session:
        trial = TendingTrial(session, PLAN, OperatorModel(reset_s=2.0))
        counters = trial.run(tail=30.0, wall_timeout=300.0)
        bender = session.bender
        assert bender is not None
        kinds = [(e.kind, e.part) for e in bender.events()]
        assert kinds == [("released", "part_001"), ("weld_broke", "part_001"),
                         ("released", "part_002")]  # fmt: skip
        assert len(trial.calls) == 1  # the robot stopped once, the operator let it go on
        assert "part in the gripper" in trial.stops[0] or "still held" in trial.stops[0]
        assert _where(session, "part_002") == "caught"  # on the rack
        assert not session.sim.gripper.is_holding()
        assert counters == TrialCounters(
            produced=2, caught=1, bad_weld=1, lost=1, operator_interventions=1,
            sim_seconds=counters.sim_seconds,
        )  # fmt: skip
        assert counters.sim_seconds > bender.plan[-1].offset


def test_a_plan_that_ends_early_ends_the_trial_even_in_lockstep(tmp_path: Path) -> None:
    """The engine stops ticking when its plan ends: the world, no longer driven by it, runs
    on by itself and the trial ends.
    """
    paper = json.loads(PLAN.read_text(encoding="utf-8"))
    watch = next(n for n in _nodes(paper["tree"]) if n.get("name") == "wait for the welding arm")
    fail = {"id": "f" * 32, "kind": "operation", "name": "give up", "op": "debug.fail"}
    paper["tree"] = {"id": "e" * 32, "kind": "sequence", "name": "watch, fail",
                     "children": [watch, fail]}  # fmt: skip
    plan = tmp_path / "ends_early.costar.json"
    plan.write_text(json.dumps(paper), encoding="utf-8")
    scene = tending_scene(tmp_path, parts=2)
    with trial_session(scene, 3) as session:
        trial = TendingTrial(session, plan, OperatorModel())
        counters = trial.run(wall_timeout=120.0)
        assert trial.ended().startswith("FAILURE")
        assert counters.produced == 1  # the trial ended with the plan, at the first part


def _trial_record(scene: Path, seed: int, faults: FaultModel) -> tuple[list[Any], list[float]]:
    """Every status change (tick, node, status) of a one-part trial, and the operator's calls."""
    with trial_session(scene, seed, faults=faults) as session:
        trial = TendingTrial(session, PLAN, OperatorModel(reset_s=2.0))
        changes: list[Any] = []
        trial.executor.add_listener(
            lambda e: (
                changes.append((e.tick, e.node_id, e.new)) if isinstance(e, StatusChanged) else None
            )
        )
        trial.run(tail=20.0, wall_timeout=300.0)
        return changes, trial.calls


def test_a_trial_run_again_with_its_seed_is_the_same_trial(tmp_path: Path) -> None:
    """In lockstep from simulated time 0, with the bender started and the operator acting at
    set simulated times: the same seed gives the same node changes at the same ticks, and
    the operator is called at the same moment (a bad weld stops the paper's plan).
    """
    scene = tending_scene(tmp_path, parts=1)
    faults = FaultModel(bad_weld=1.0, bad_grasp=0.0)
    first, calls = _trial_record(scene, 5, faults)
    again, calls_again = _trial_record(scene, 5, faults)
    assert len(first) > 20 and len(calls) == 1
    assert again == first
    assert calls_again == calls


def _nodes(node: dict[str, Any]) -> list[dict[str, Any]]:
    return [node, *(n for child in node.get("children", []) for n in _nodes(child))]
