"""The paper's Figure 3 task on the simulated cell: resources/examples/cup_to_bin.costar.json.

Each seed places the cup and the bin elsewhere; the plan finds them through their markers in
rendered images. Ground truth is read here only, to check that the cup ended in the bin.
"""

from __future__ import annotations

import io
import json
import time
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.cli import main as costar
from capabilities.sim.session import PERCEPTION_S, SimCellSession
from engine.build import build_tree
from engine.executor import run_to_end
from engine.files import load_plan
from engine.status import Status
from engine.types import Pose
from engine.validation import has_errors, validate_plan

PLAN = Path(__file__).resolve().parents[3] / "resources" / "examples" / "cup_to_bin.costar.json"
BIN_INNER_HALF = (0.19 - 0.01, 0.10 - 0.01)  # waste bin 380 x 200 mm, walls ~10 mm
BIN_HEIGHT = 0.22


def cup_in_bin(cup: Pose, bin_pose: Pose) -> bool:
    local = bin_pose.inverse().compose(cup).position
    return (
        abs(local[0]) < BIN_INNER_HALF[0]
        and abs(local[1]) < BIN_INNER_HALF[1]
        and local[2] < BIN_HEIGHT
    )


def _run(session: SimCellSession, timeout: float = 60.0) -> Status:
    registry = CapabilityRegistry(cell=session)
    plan = load_plan(PLAN, registry.aliases())
    assert not has_errors(validate_plan(plan, registry))
    tree = build_tree(plan, registry, clock=session.clock)
    return run_to_end(tree, 50.0, timeout, lockstep=session.run_lockstep()).status


@pytest.mark.parametrize("seed", range(20))
def test_cup_ends_in_the_bin(seed: int) -> None:
    # In lockstep from simulated time 0, as `costar run` runs it: the same run every time.
    with SimCellSession("cup_to_bin", seed, lockstep=PERCEPTION_S, still_until_run=True) as session:
        assert _run(session) is Status.SUCCESS
        session.sim.wait_sim(1.0)  # let the cup settle
        assert cup_in_bin(session.truth_pose("cup"), session.truth_pose("waste_bin"))


def test_waits_while_the_cup_is_hidden_and_completes_when_it_appears() -> None:
    with SimCellSession("cup_to_bin", seed=3) as session:
        cup_pose = session.truth_pose("cup")
        session.sim.call(lambda client: session.scene.remove(client, "cup"))
        registry = CapabilityRegistry(cell=session)
        tree = build_tree(load_plan(PLAN), registry, clock=session.clock)
        seen = []
        tree.ctx.status_sink = lambda node, old, new: seen.append((node.name, new))
        # Tick by hand (paced by simulated time) until the plan has fallen back to Wait
        # twice. The bound is wall time: detection runs on a worker thread at its own pace.
        deadline = time.monotonic() + 120.0
        while tree.root.runs < 2 and time.monotonic() < deadline:
            tree.tick()
            session.sim.wait_sim(0.05)
        assert tree.root.runs >= 2 and tree.status is Status.RUNNING
        assert ("Wait", Status.RUNNING) in seen
        session.sim.call(lambda client: session.scene.spawn(client, "cup", "cup", cup_pose))
        deadline = time.monotonic() + 120.0
        while tree.tick() is Status.RUNNING and time.monotonic() < deadline:
            session.sim.wait_sim(0.02)
        assert tree.status is Status.SUCCESS
        session.sim.wait_sim(1.0)
        assert cup_in_bin(session.truth_pose("cup"), session.truth_pose("waste_bin"))


def test_costar_run_on_the_sim_cell_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    assert costar(["run", str(PLAN), "--cell", "sim", "--seed", "5", "--rate", "50", "--fast"]) == 0
    assert "SUCCESS" in capsys.readouterr().out


def _transitions(trace: Path) -> list[tuple[int, str, str]]:
    lines = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    return [(e["tick"], e["node"], e["new"]) for e in lines if e.get("event") == "status"]


@pytest.mark.sim
def test_costar_run_on_the_simulated_cell_gives_the_same_run_twice(tmp_path: Path) -> None:
    """Lockstep: the same plan, scene and seed give the same node transitions at the same
    ticks, whatever else the machine does meanwhile (seed 61 used to differ at its 12th).
    """
    runs = []
    for name in ("first", "second"):
        trace = tmp_path / f"{name}.jsonl"
        out, err = io.StringIO(), io.StringIO()
        args = [
            "run",
            str(PLAN),
            "--seed",
            "61",
            "--trace",
            str(trace),
            "--timeout",
            "120",
            "--fast",
        ]
        assert costar(args, out, err) == 0, out.getvalue() + err.getvalue()
        runs.append(_transitions(trace))
    assert len(runs[0]) > 20
    assert runs[0] == runs[1]


@pytest.mark.sim
def test_runs_replay_gives_the_recorded_run_again_or_says_where_it_parts(tmp_path: Path) -> None:
    """A paced run (as a worker runs it) replayed as fast as it can is the same run; a record
    whose fifth status change came a tick later is named as parting there.
    """
    runs = tmp_path / "runs"
    out, err = io.StringIO(), io.StringIO()
    args = ["run", str(PLAN), "--seed", "61", "--runs", str(runs), "--timeout", "120"]
    assert costar(args, out, err) == 0, out.getvalue() + err.getvalue()
    out, err = io.StringIO(), io.StringIO()
    assert costar(["runs", "replay", "last", "--runs", str(runs)], out, err) == 0, err.getvalue()
    assert out.getvalue().startswith("the same run: ")
    record = next(runs.iterdir())
    lines = record.read_text(encoding="utf-8").splitlines()
    changes = [i for i, line in enumerate(lines) if json.loads(line).get("event") == "status"]
    fifth = json.loads(lines[changes[4]])
    lines[changes[4]] = json.dumps(fifth | {"tick": fifth["tick"] + 1})
    record.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out, err = io.StringIO(), io.StringIO()
    assert costar(["runs", "replay", str(record)], out, err) == 1, err.getvalue()
    assert out.getvalue().startswith("the runs part at status change 5: recorded tick ")
