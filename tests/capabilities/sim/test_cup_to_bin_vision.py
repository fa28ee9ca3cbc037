"""Figure 3 by vision: resources/examples/cup_to_bin_vision.costar.json on the simulated cell.

The plan finds the cup and the waste bin by matching the shoulder camera's point cloud to
their models (perception), not by markers. Ground truth is read here only, to check that
the cup ended in the bin.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.gripper import capability as gripper
from capabilities.motion import capability as motion
from capabilities.perception import capability as perception
from capabilities.sim.session import PERCEPTION_S, SimCellSession
from capabilities.timing import capability as timing
from engine.build import build_tree
from engine.executor import run_to_end
from engine.files import load_plan
from engine.status import Status
from engine.validation import has_errors, validate_plan
from tests.capabilities.sim.test_cup_to_bin import cup_in_bin

PLAN = (
    Path(__file__).resolve().parents[3] / "resources" / "examples" / "cup_to_bin_vision.costar.json"
)


def _run(session: SimCellSession, timeout: float = 60.0) -> tuple[Status, str]:
    registry = CapabilityRegistry([motion(), gripper(), timing(), perception()], cell=session)
    plan = load_plan(PLAN, registry.aliases())
    assert not has_errors(validate_plan(plan, registry))
    tree = build_tree(plan, registry, clock=session.clock)
    result = run_to_end(tree, 50.0, timeout, lockstep=session.run_lockstep())
    messages = " | ".join(f"{n.name}: {n.message}" for n in tree.iterate() if n.message)
    return result.status, messages


@pytest.mark.parametrize("seed", range(20))
def test_cup_ends_in_the_bin(seed: int) -> None:
    # In lockstep from simulated time 0, as `costar run` runs it: the same run every time.
    with SimCellSession("cup_to_bin", seed, lockstep=PERCEPTION_S, still_until_run=True) as session:
        status, messages = _run(session)
        assert status is Status.SUCCESS, messages
        session.sim.wait_sim(1.0)  # let the cup settle
        assert cup_in_bin(session.truth_pose("cup"), session.truth_pose("waste_bin"))
        assert session.world_model.best("cup") is not None
