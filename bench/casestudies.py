"""The paper's case studies on the simulated cell: how often each shipped plan succeeds.

Each case study runs its shipped plan through the engine on the simulated cell, one run per
scene seed (the seed draws where the objects lie and when the worker acts), and scores the
outcome with the simulator's ground truth (ground truth only scores; the plan perceives
through the cameras). A run succeeded when the plan returned SUCCESS *and* the scorer agrees
that the task was done.

- ``tending`` (section V-B, Table I): the paper's plan and ours tend the wire bender for two
  trials of ``--parts`` parts from ``--seed`` on (see ``bench/_tending.py``); their counters
  are printed side by side with the paper's Table I.
- ``tending_record`` (with ``tending``): the size of the tending plan's run record per hour
  (goal at most 50 MB): one trial of ``--record-parts`` parts of our plan paced at real time
  (as on the cell: the record's samples come per wall second, the plan's events per
  simulated second) writes its record as `costar run` does (events, joints at 10 Hz, a
  160x120 JPEG of each camera a second); its bytes over the time its run took, times an
  hour (``bench/_tending.py``: ``measure_record_size``).
- ``kitting``: resources/examples/kitting.costar.json on scene ``kitting_handoff`` (Figure 7):
  each of the three plates lies inside the kit bin and the bin stands at the return place.
- ``cup_to_bin``: resources/examples/cup_to_bin_vision.costar.json on scene ``cup_to_bin``
  (Figure 3, found by vision): the cup lies in the waste bin.

To add a seeded case study, add a :class:`CaseStudy` to ``CASES``: its plan, scene and a
scorer ``(session) -> str`` that returns "" when the task was done, else what is wrong. Run
from the repository root::

    .venv/bin/python bench/casestudies.py [--runs 100] [--only kitting] [--seed 1000]
        [--parts 50] [--record-parts 2] [--json]

JSON: ``{"tending": {"paper": {"produced": 100, "caught": 80, ...}, "ours": {...}},
"kitting": {"runs": 100, "succeeded": 99, "failures": {"seed": "why", ...},
"wall_s_per_run": 17.2}, "cup_to_bin": {...}, "tending_record": {"mb_per_hour": 21.5,
"bytes": ..., "run_s": ..., "mb_per_hour_by_kind": {...}, ...}}`` (wall seconds per run, divided by ``--jobs``
in effect).
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench._tending import (  # noqa: E402
    PLANS,
    RESET_S,
    SPEED,
    c_output_to_stderr,
    measure_record_size,
    measure_tending,
    table_one,
)
from capabilities.base import CapabilityRegistry  # noqa: E402
from capabilities.sim.session import PERCEPTION_S, SimCellSession  # noqa: E402
from engine.build import build_tree  # noqa: E402
from engine.executor import run_to_end  # noqa: E402
from engine.files import load_plan  # noqa: E402
from engine.status import Status  # noqa: E402
from engine.types import Pose  # noqa: E402
from engine.validation import has_errors, validate_plan  # noqa: E402

EXAMPLES = ROOT / "resources" / "examples"
RUN_TIMEOUT = 600.0  # wall seconds: a run that takes longer counts as failed


@dataclass(frozen=True)
class CaseStudy:
    """A shipped plan, the scene it runs in and how its outcome is scored."""

    plan: Path
    scene: str
    score: Callable[[SimCellSession], str]


def _in_frame(frame: Pose, pose: Pose) -> tuple[float, float, float]:
    x, y, z = frame.inverse().compose(pose).position
    return x, y, z


BIN_INSIDE = (0.175, 0.1275)  # m: half the bin's inner length and width
RETURN_AT = (0.5, -0.12)  # where the kitting plan puts the bin (make_kitting.RETURN_AT)
PLATES = ("plate_3_holes", "plate_4_holes", "plate_8_holes")


def score_kitting(session: SimCellSession) -> str:
    """'' when every plate lies in the bin and the bin stands at the return place."""
    session.sim.wait_sim(0.5)  # let what was let go settle
    bin_pose = session.truth_pose("kit_bin")
    problems = []
    for plate in PLATES:
        x, y, z = _in_frame(bin_pose, session.truth_pose(plate))
        if abs(x) > BIN_INSIDE[0] or abs(y) > BIN_INSIDE[1] or not 0.0 < z < 0.03:
            problems.append(f"{plate} not in the bin ({x:.3f}, {y:.3f}, {z:.3f}) m")
    away = math.dist(bin_pose.position[:2], RETURN_AT)
    if away > 0.03:
        problems.append(f"bin {away * 1000:.0f} mm from the return place")
    return "; ".join(problems)


CUP_IN_BIN = (0.18, 0.09, 0.22)  # m: half the waste bin's inner length and width, its height


def score_cup_to_bin(session: SimCellSession) -> str:
    """'' when the cup lies in the waste bin."""
    session.sim.wait_sim(1.0)  # let the dropped cup settle
    x, y, z = _in_frame(session.truth_pose("waste_bin"), session.truth_pose("cup"))
    if abs(x) < CUP_IN_BIN[0] and abs(y) < CUP_IN_BIN[1] and z < CUP_IN_BIN[2]:
        return ""
    return f"the cup is not in the bin ({x:.3f}, {y:.3f}, {z:.3f}) m"


CASES: dict[str, CaseStudy] = {
    "kitting": CaseStudy(EXAMPLES / "kitting.costar.json", "kitting_handoff", score_kitting),
    "cup_to_bin": CaseStudy(
        EXAMPLES / "cup_to_bin_vision.costar.json", "cup_to_bin", score_cup_to_bin
    ),
}
TENDING = "tending"
RECORD = "tending_record"  # the size of the tending plan's run record per hour


def run_case(case: CaseStudy, seed: int) -> str:
    """'' when the run of one seed succeeded, else why not."""
    # In lockstep from simulated time 0, as `costar run` runs it: a seed's run is the same on
    # any machine and beside any load.
    with SimCellSession(case.scene, seed, lockstep=PERCEPTION_S, still_until_run=True) as session:
        registry = CapabilityRegistry(cell=session)
        plan = load_plan(case.plan, aliases=registry.aliases())
        problems = validate_plan(plan, registry)
        if has_errors(problems):
            return "invalid: " + "; ".join(str(p) for p in problems if p.severity == "error")
        tree = build_tree(plan, registry, clock=session.clock)
        result = run_to_end(tree, 20.0, RUN_TIMEOUT, lockstep=session.run_lockstep())
        if result.status is not Status.SUCCESS:
            return f"{result.status.value}: {result.message or result.reason}"
        return case.score(session)


def _run_seed(job: tuple[str, int]) -> tuple[int, str]:
    name, seed = job
    try:
        why = run_case(CASES[name], seed)
    except Exception as exc:  # a crash of one run is a failed run, not the end of the bench
        why = f"error: {type(exc).__name__}: {exc}"
    print(f"{name} seed {seed}: {why or 'ok'}", file=sys.stderr, flush=True)
    return seed, why


def measure(name: str, runs: int, first_seed: int = 0, jobs: int = 1) -> dict[str, Any]:
    """Run ``runs`` seeds of a case study, ``jobs`` cells at a time (each its own process)."""
    seeds = [(name, seed) for seed in range(first_seed, first_seed + runs)]
    start = time.perf_counter()
    if jobs > 1:
        with multiprocessing.get_context("spawn").Pool(jobs) as pool:
            results = pool.map(_run_seed, seeds, chunksize=1)
    else:
        results = [_run_seed(job) for job in seeds]
    failures = {str(seed): why for seed, why in results if why}
    wall = (time.perf_counter() - start) / max(runs, 1)
    return {
        "runs": runs,
        "succeeded": runs - len(failures),
        "failures": failures,
        "wall_s_per_run": round(wall, 1),
    }


def _arguments(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--runs", type=int, default=100, help="seeds per seeded case study")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--only", choices=sorted([TENDING, *CASES]), action="append")
    parser.add_argument("--jobs", type=int, default=1, help="cells run at once (processes)")
    parser.add_argument("--seed", type=int, default=1000, help="tending: trial i runs seed+i")
    parser.add_argument("--parts", type=int, default=50, help="tending: parts per trial")
    parser.add_argument("--trials", type=int, default=2, help="tending: trials per plan")
    parser.add_argument(
        "--pairs",
        type=int,
        default=0,
        help="tending: this many pairs of trials per plan (instead of --trials), each "
        "figure printed as its mean (min-max) over the pairs",
    )
    parser.add_argument(
        "--reset-s",
        type=float,
        default=RESET_S,
        help="tending: simulated seconds the operator takes to reset the cell",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=SPEED or 0.0,
        help="tending: times real time at most (0: as fast as lockstep allows)",
    )
    parser.add_argument("--plan", choices=sorted(PLANS), action="append",
                        help="tending: only this plan (default: both)")  # fmt: skip
    parser.add_argument(
        "--record-parts",
        type=int,
        default=2,
        help="tending_record: parts of the paced trial whose run record is "
        "measured (0: no tending_record)",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    return parser.parse_args(argv)  # fmt: skip


def _print(figures: dict[str, Any]) -> None:
    for name, fig in figures.items():
        if name == RECORD:
            print(
                f"tending record: {fig['mb_per_hour']} MB per hour (goal <= 50): "
                f"{fig['bytes']} bytes over {fig['run_s']} s of a {fig['parts']}-part trial of "
                f"the {fig['plan']} plan at real time, scaled to an hour; by kind (MB/h): "
                + ", ".join(f"{k} {v}" for k, v in fig["mb_per_hour_by_kind"].items())
            )
            continue
        if name == TENDING:
            print(table_one(fig))
            for plan, entry in fig.items():
                for error in entry.get("errors", []):
                    print(f"  tending {plan}: {error}")
            continue
        print(f"{name}: {fig['succeeded']}/{fig['runs']} succeeded, {fig['wall_s_per_run']} s/run")
        for seed, why in fig["failures"].items():
            print(f"  seed {seed}: {why}")


def _measure_all(args: argparse.Namespace) -> dict[str, Any]:
    figures: dict[str, Any] = {}
    for name in args.only or [TENDING, *CASES]:
        if name == TENDING:
            speed = args.speed or None
            figures[name] = measure_tending(
                args.seed,
                args.parts,
                args.trials,
                args.jobs,
                args.reset_s,
                speed,
                args.plan,
                args.pairs,
            )
        else:
            figures[name] = measure(name, args.runs, args.first_seed, args.jobs)
    if TENDING in (args.only or [TENDING]) and args.record_parts > 0:
        figures[RECORD] = measure_record_size(args.seed, args.record_parts)
    return figures


def main(argv: list[str] | None = None) -> int:
    """Run every case study (or ``--only`` some) and print the figures."""
    args = _arguments(argv)
    with c_output_to_stderr():
        figures = _measure_all(args)
    if args.json:
        print(json.dumps(figures))
    else:
        _print(figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
