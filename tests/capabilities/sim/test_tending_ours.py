"""Our wire-bender tending plan (resources/examples/tending.costar.json) in short trials on
the ``tending`` scene: each fault is recovered by its library subtree with no operator (a
slipped grasp by Regrasp, a broken weld by DiscardToScrap, a moved rack by ReRegisterRack,
a collision while placing by ClearStopAndBackOff and ReRegisterRack). Each is also a short
trial of ours (one or two parts). The cell runs in
lockstep from simulated time 0 (``trial_session``), as the benches run it. Ground truth
is read here only, to set the faults up and to score.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from capabilities.sim.bender import read_bender
from capabilities.sim.bender_spec import FaultModel, plan_parts
from capabilities.sim.objects import set_object_frame_pose
from capabilities.sim.session import SimCellSession
from capabilities.sim.tending_score import TrialCounters, container_of
from capabilities.sim.tending_trial import OperatorModel, TendingTrial, trial_session
from engine.events import Event, StatusChanged
from engine.status import Status
from engine.types import Pose
from tests.capabilities.sim.test_bender import tending_scene

PLAN = Path(__file__).resolve().parents[3] / "resources" / "examples" / "tending.costar.json"
NOBODY = OperatorModel(present=False)  # ours never calls the operator


def _where(session: SimCellSession, part: str) -> str:
    """GROUND TRUTH: 'caught' (in the rack's tote), 'scrapped' or ''."""
    scene = session.scene
    return session.sim.call(lambda c: container_of(c, scene, scene.truth_pose(c, part)))


def _seed_with(
    faults: list[tuple[bool, bool]], rates: FaultModel, scene: Path, shape: str = ""
) -> int:
    """A seed whose parts have these (bad weld, bad grasp) faults (the first part this shape)."""
    spec = read_bender(scene)
    assert spec is not None
    for seed in range(500):
        parts = plan_parts(spec, seed, rates)
        if [(p.bad_weld, p.bad_grasp) for p in parts] == faults and shape in parts[0].shape:
            return seed
    raise AssertionError(f"no seed gives faults {faults} with a {shape} first")


def _session(scene: Path, seed: int, rates: FaultModel) -> SimCellSession:
    return trial_session(scene, seed, faults=rates)


class _Watched(TendingTrial):
    """A trial that also notes which of the plan's nodes ran (by label)."""

    def __init__(self, session: SimCellSession) -> None:
        self.ran: set[str] = set()
        super().__init__(session, PLAN, NOBODY)

    def _heard(self, event: Event) -> None:
        super()._heard(event)
        if isinstance(event, StatusChanged) and event.new is Status.RUNNING:
            self.ran.add(self.node(event.node_id)[0])


def _trial(session: SimCellSession) -> tuple[TrialCounters, _Watched]:
    trial = _Watched(session)
    return trial.run(tail=40.0, wall_timeout=400.0), trial


def test_a_slipped_grasp_is_regrasped(tmp_path: Path) -> None:
    """Part 1 slips out of the first grasp: Regrasp takes it again and it ends on the rack;
    part 2 is good and ends there too. The operator is never called.
    """
    scene = tending_scene(tmp_path, parts=2, interval=24.0)
    rates = FaultModel(bad_weld=0.0, bad_grasp=0.5, interval_spread=0.0)
    seed = _seed_with([(False, True), (False, False)], rates, scene)
    with _session(scene, seed, rates) as session:
        counters, trial = _trial(session)
        bender = session.bender
        assert bender is not None
        assert [(e.kind, e.part) for e in bender.events() if e.kind != "released"] == [
            ("slipped", "part_001")
        ]
        assert "Regrasp" in trial.ran and "DiscardToScrap" not in trial.ran
        assert [_where(session, p) for p in ("part_001", "part_002")] == ["caught"] * 2
        assert counters.caught == 2 and trial.calls == []


@pytest.mark.parametrize("shape", ["wireform_u", "wireform_step"])
def test_a_broken_weld_is_discarded_without_the_operator(tmp_path: Path, shape: str) -> None:
    """Part 1's weld comes apart when lifted: Regrasp gives up and DiscardToScrap takes over
    (both pieces into the scrap bin, wherever each shape's lie) until the next part comes,
    which is caught. The run goes on: the operator is never called and no protective stop
    holds it.
    """
    scene = tending_scene(tmp_path, parts=2, interval=24.0)
    rates = FaultModel(bad_weld=0.5, bad_grasp=0.0, interval_spread=0.0)
    seed = _seed_with([(True, False), (False, False)], rates, scene, shape)
    with _session(scene, seed, rates) as session:
        counters, trial = _trial(session)
        bender = session.bender
        assert bender is not None
        assert [(e.kind, e.part) for e in bender.events() if e.kind != "released"] == [
            ("weld_broke", "part_001")
        ]
        assert {"Regrasp", "DiscardToScrap", "recover and go on"} <= trial.ran
        assert trial.calls == [] and counters.operator_interventions == 0
        assert counters.produced == 2
        assert (counters.scrapped, counters.caught) == (1, 1), (trial.failures, trial.lost())


def _once(session: SimCellSession, when: Callable[[int], bool], act: Callable[[int], None]) -> None:
    """On the physics thread: ``act`` once, at the first step where ``when`` holds."""
    client = session.sim.call(lambda c: c)
    done = [False]

    def hook(_now: float) -> None:
        if not done[0] and when(client):
            done[0] = True
            act(client)

    session.sim.add_step_hook(post=hook)


def _move_rack(session: SimCellSession, client: int, dx: float, dy: float, dyaw: float) -> None:
    """GROUND TRUTH: a worker moves the rack (by dx, dy in the world, turned by dyaw)."""
    rack = session.scene.objects["rack"]
    (x, y, z), turn = session.scene.truth_pose(client, "rack").position, _yaw(dyaw)
    pose = Pose((x + dx, y + dy, z), turn.orientation)
    pose = Pose(pose.position, _multiply(turn, session.scene.truth_pose(client, "rack")))
    set_object_frame_pose(client, rack.body_id, rack.model, pose)


def _yaw(yaw: float) -> Pose:
    return Pose((0.0, 0.0, 0.0), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


def _multiply(turn: Pose, pose: Pose) -> tuple[float, float, float, float]:
    """The orientation of ``pose`` turned by ``turn`` about the world's vertical."""
    return turn.compose(Pose((0.0, 0.0, 0.0), pose.orientation)).orientation


def test_a_rack_moved_while_the_robot_picks_is_found_again(tmp_path: Path) -> None:
    """The rack is pushed 19 cm away from the robot and turned while the robot takes the part
    at the exit: a drop where the rack was would miss its tote; ReRegisterRack finds it again before the
    place and the part ends in the tote.
    """
    scene = tending_scene(tmp_path, parts=1)
    rates = FaultModel(bad_weld=0.0, bad_grasp=0.0)
    with _session(scene, 4, rates) as session:
        bender = session.bender
        assert bender is not None
        before = session.truth_pose("rack")
        _once(session, lambda c: bool(bender.produced()),
              lambda c: _move_rack(session, c, 0.0, -0.19, -0.3))  # fmt: skip
        counters, trial = _trial(session)
        moved = session.truth_pose("rack")
        assert math.dist(before.position, moved.position) > 0.17  # out of the old tote
        assert _where(session, "part_001") == "caught", (trial.failures, trial.lost())
        assert counters.caught == 1 and trial.calls == []


def test_a_collision_while_placing_is_cleared_and_the_part_placed_again(tmp_path: Path) -> None:
    """Once the robot holds the part over the rack, the rack is pushed sideways and lifted
    6 cm (its wall under the tool): the fingers hit the wall on the way down, a protective
    stop. ClearStopAndBackOff clears it and backs off, ReRegisterRack finds the rack again
    and the second place puts the part into its tote.
    """
    scene = tending_scene(tmp_path, parts=1)
    rates = FaultModel(bad_weld=0.0, bad_grasp=0.0)
    with _session(scene, 4, rates) as session:

        def over_the_rack(client: int) -> bool:
            if "part_001" not in session.scene.objects:
                return False
            part = session.scene.truth_pose(client, "part_001").position
            tote = session.scene.truth_pose(client, "rack").compose(Pose((0.04, 0.0, 0.0)))
            return part[2] > 0.25 and math.dist(part[:2], tote.position[:2]) < 0.05

        def push(client: int) -> None:  # GROUND TRUTH: its +y wall under the tool, lifted
            rack = session.scene.objects["rack"]
            frame = session.scene.truth_pose(client, "rack")
            moved = frame.compose(Pose((0.0, -0.167, 0.06)))
            set_object_frame_pose(client, rack.body_id, rack.model, moved)

        _once(session, over_the_rack, push)
        counters, trial = _trial(session)
        assert {"ClearStopAndBackOff", "ReRegisterRack", "PlaceOnRack again"} <= trial.ran
        assert _where(session, "part_001") == "caught"
        assert counters.caught == 1 and trial.calls == []
        assert session.sim.robot.protective_stop() is None  # cleared
