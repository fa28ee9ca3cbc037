"""The paper's wire-bender tending plan (resources/examples/tending_paper.costar.json) in a
short trial on the ``tending`` scene: a bad weld stops the robot until the operator presses
Continue, while the bender goes on; the next, good part ends on the rack. Ground truth is
read here only."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from capabilities.base import CapabilityRegistry
from capabilities.sim.bender import read_bender
from capabilities.sim.bender_spec import FaultModel, plan_parts
from capabilities.sim.session import SimCellSession
from engine.build import build_tree
from engine.events import Event, StatusChanged
from engine.executor import Executor
from engine.files import load_plan
from engine.status import Status
from engine.validation import has_errors, validate_plan
from tests.capabilities.sim.test_bender import tending_scene

PLAN = Path(__file__).resolve().parents[3] / "resources" / "examples" / "tending_paper.costar.json"
OPERATOR = "operator resets the cell, presses Continue"
WATCH = "wait for the welding arm"
# Paced: perception takes wall time, and as fast as possible a part could come and go while
# a camera's image is searched. Twice real time leaves room for a loaded CI machine (at four
# times, two parallel test workers made the robot miss part 2 once).
SPEED = 2.0


class Trial:
    """Runs the plan on a session of the scene; starts the bender when the robot first
    watches its arm (set up, as on site); counts the operator's waits, presses Continue for
    each (``press``)."""

    def __init__(self, session: SimCellSession, press: bool) -> None:
        self.session = session
        self.waits = 0
        self._press = press
        self._lock = threading.Lock()
        registry = CapabilityRegistry(cell=session)
        plan = load_plan(PLAN, registry.aliases())
        assert not has_errors(validate_plan(plan, registry))
        self._names = {node.id: node.name for _, node in plan.walk()}
        tree = build_tree(plan, registry, clock=session.clock)
        self.executor = Executor(tree, 50.0, [self._heard])

    def _heard(self, event: Event) -> None:
        if not isinstance(event, StatusChanged) or event.new is not Status.RUNNING:
            return
        if self._names.get(event.node_id) == WATCH:
            self.session.start_actors()  # from the first watch on; later calls do nothing
        if self._names.get(event.node_id) == OPERATOR:
            with self._lock:
                self.waits += 1
            if self._press:
                self.session.operator.press("continue")

    def run(self, until: float) -> None:
        """Run the plan until ``until`` simulated seconds after the bender started."""
        self.executor.start()
        bender = self.session.bender
        assert bender is not None
        deadline = time.monotonic() + 300.0  # a generous wall-time bound
        while bender.start_time is None or self.session.clock() - bender.start_time < until:
            assert time.monotonic() < deadline, "the trial did not reach its simulated time"
            self.session.sim.wait_sim(0.5)
        self.executor.stop("trial over")
        assert self.executor.wait(10.0) is not None


def on_rack(session: SimCellSession, part: str) -> bool:
    """GROUND TRUTH: the part lies in the rack's tote."""
    if part not in session.scene.objects:
        return False
    tote = session.scene.model("rack").extra["tote"]
    local = session.truth_pose("rack").inverse().compose(session.truth_pose(part)).position
    inner = tote["inner"]
    return (abs(local[0] - tote["center"][0]) < inner[0] / 2
            and abs(local[1] - tote["center"][1]) < inner[1] / 2
            and tote["floor"] - 0.002 < local[2] < 0.08)  # fmt: skip


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
    the operator; after Continue it catches part 2 and puts it on the rack."""
    scene = tending_scene(tmp_path, parts=2, interval=18.0)
    faults = FaultModel(bad_weld=0.5, bad_grasp=0.0, interval_spread=0.0)
    seed = _seed_with([True, False], faults, scene)
    # The shoulder camera at its full 640 x 480: at 320 x 240 the rack's marker is too small
    # to be found from some of the rack's poses.
    with SimCellSession(scene, seed, speed=SPEED, faults=faults, start_actors=False) as session:
        trial = Trial(session, press=True)
        bender = session.bender
        assert bender is not None
        trial.run(until=bender.plan[-1].offset + 30.0)
        kinds = [(e.kind, e.part) for e in bender.events()]
        assert kinds == [("released", "part_001"), ("weld_broke", "part_001"),
                         ("released", "part_002")]  # fmt: skip
        assert trial.waits == 1  # the robot stopped once, the operator let it go on
        assert on_rack(session, "part_002")
        assert not session.sim.gripper.is_holding()
