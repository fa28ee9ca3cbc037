"""The tending case study of ``bench/casestudies.py``: the paper's Table I, in simulation.

Each plan (the paper's ``tending_paper.costar.json`` and ours, ``tending.costar.json``) runs
``trials`` trials of ``parts`` parts on the ``tending`` scene (trial i on seed ``seed + i``;
the same seeds, hence the same parts and faults, for both plans) through
``capabilities/sim/tending_trial.py``; the counters of the trials are added up as Table I
does. The simulated cell runs in lockstep: it goes on only with the engine's 50 Hz ticks,
its time stands still while perception computes (each job then takes ``PERCEPTION_S``
simulated seconds), and the run starts at simulated time 0; otherwise as fast as it can, or
at ``speed`` times real time. A trial is the same every time it runs with the same seed.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capabilities.sim.tending_score import TrialCounters
from capabilities.sim.tending_trial import OperatorModel, TendingTrial, trial_session

__all__ = [
    "PAPER",
    "PLANS",
    "TendingJob",
    "c_output_to_stderr",
    "measure_record_size",
    "measure_tending",
    "table_one",
]

EXAMPLES = Path(__file__).resolve().parents[1] / "resources" / "examples"
PLANS = {"paper": EXAMPLES / "tending_paper.costar.json", "ours": EXAMPLES / "tending.costar.json"}
# Table I and its text: two trials of 50 parts at Marlin Steel.
PAPER = {"produced": 100, "caught": 82, "bad_weld": 2, "bad_grasp": 5, "lost_to_stops": 13}
PAPER_PROJECTED = 93  # % the authors projected with better error handling
RESET_S = 30.0  # simulated seconds the operator takes to reset the cell (see the README)
SPEED: float | None = None  # as fast as lockstep allows


@contextmanager
def c_output_to_stderr() -> Iterator[None]:
    """Send what C code prints to stdout (pybullet's warnings) to stderr meanwhile, so that
    stdout keeps the one JSON object of ``--json`` (cells of a pool started inside too).
    """
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


@dataclass(frozen=True)
class TendingJob:
    """One trial: which plan, seed and number of parts, the operator and the pacing."""

    plan: str
    seed: int
    parts: int
    reset_s: float = RESET_S
    speed: float | None = SPEED


def run_trial(job: TendingJob) -> dict[str, Any]:
    """One trial's counters (as JSON values), the failures that called the operator, the wall
    time; a crash is reported as ``error`` (a bench goes on).
    """
    started = time.perf_counter()
    try:
        with trial_session("tending", job.seed, job.speed) as session:
            operator = OperatorModel(reset_s=job.reset_s)
            trial = TendingTrial(session, PLANS[job.plan], operator)
            counters = trial.run(parts=job.parts, wall_timeout=300.0 * job.parts)
            out: dict[str, Any] = counters.as_dict() | {"stops": trial.stops}
            out["lost_parts"] = trial.lost()  # what became of each, and what failed then
            if trial.ended():  # the plan ended before the trial did: what failed last
                out["plan_ended"] = trial.ended()
                out["last_failures"] = trial.failures[-5:]
    except Exception as exc:  # one broken trial must not end the bench
        out = {"error": f"{type(exc).__name__}: {exc}"}
    out |= {"seed": job.seed, "wall_s": round(time.perf_counter() - started, 1)}
    print(f"tending {job.plan} seed {job.seed}: {out}", file=sys.stderr, flush=True)
    return out


def _total(trials: list[dict[str, Any]]) -> dict[str, Any]:
    """The trials' counters added up (Table I's rows), with each trial's own."""
    total = TrialCounters()
    fields = set(TrialCounters.__dataclass_fields__)
    for trial in trials:
        if "error" not in trial:
            total = total + TrialCounters(**{k: v for k, v in trial.items() if k in fields})
    errors = [t["error"] for t in trials if "error" in t]
    return total.as_dict() | {"trials": trials, "errors": errors}


def _spread(trials: list[dict[str, Any]], per_pair: int) -> dict[str, Any]:
    """Table I of each pair of trials (consecutive seeds) and each row's mean, minimum and
    maximum over the pairs: one pair of 50-part trials says little about random faults.
    """
    pairs = [trials[i : i + per_pair] for i in range(0, len(trials), per_pair)]
    tables = [_total(pair) for pair in pairs]
    rows = {
        row: [float(t[row]) for t in tables if not t["errors"]] for row in (*ROWS, "sim_seconds")
    }
    spread = {
        row: {"mean": round(sum(v) / len(v), 1), "min": min(v), "max": max(v)}
        for row, v in rows.items()
        if v
    }
    pair_rows = [{k: t[k] for k in (*ROWS, "sim_seconds", "errors")} for t in tables]
    return {"pairs": pair_rows, "spread": spread}


def measure_tending(
    seed: int, parts: int, trials: int = 2, jobs: int = 1, reset_s: float = RESET_S,
    speed: float | None = SPEED, only: list[str] | None = None, pairs: int = 0,
) -> dict[str, Any]:  # fmt: skip
    """{"paper": {...}, "ours": {...}}: each plan's counters over ``trials`` trials
    (ours: {"skipped": why} while resources/examples/tending.costar.json does not exist;
    a plan left out of ``only``: {"skipped": "not asked for"}). With ``pairs``, that many
    pairs of trials (seeds seed, seed + 1; seed + 2, seed + 3; ...) instead, each plan's
    figures with ``"pairs"`` (each pair's Table I) and ``"spread"`` (each row's mean,
    minimum and maximum over the pairs).
    """
    if pairs:
        trials = 2 * pairs
    asked = [name for name in PLANS if only is None or name in only]
    plans = [name for name in asked if PLANS[name].is_file()]
    work = [TendingJob(p, seed + i, parts, reset_s, speed) for p in plans for i in range(trials)]
    if jobs > 1:
        with multiprocessing.get_context("spawn").Pool(jobs) as pool:
            results = pool.map(run_trial, work, chunksize=1)
    else:
        results = [run_trial(job) for job in work]
    figures: dict[str, Any] = {}
    for name, path in PLANS.items():
        if name not in plans:
            why = "not asked for" if name not in asked else f"{path.name} does not exist yet"
            figures[name] = {"skipped": why}
            continue
        mine = [r for j, r in zip(work, results, strict=True) if j.plan == name]
        figures[name] = _total(mine) | (_spread(mine, 2) if pairs else {})
    return figures


def measure_record_size(
    seed: int, parts: int, speed: float | None = 1.0, plan: str = "ours"
) -> dict[str, Any]:
    """The size of the tending plan's run record per hour: one trial of ``parts`` parts
    paced at ``speed`` times real time, its record's bytes (by record kind) over the time
    its run took, scaled to an hour (the header, the plan as it ran, counted once). Paced at real time (1.0), as on the cell, the record's
    samples (joints ten times a wall second, a picture of each camera a wall second) and the
    plan's events (simulated time) come at the rates a real hour gives.
    """
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="costar-tending-record-") as folder:
        record = Path(folder) / "tending.trace.jsonl"
        with trial_session("tending", seed, speed) as session:
            trial = TendingTrial(session, PLANS[plan], OperatorModel(), record=record)
            trial.run(parts=parts, wall_timeout=300.0 * parts)
            sim_s = session.clock()
        kinds: dict[str, int] = {}
        times: list[float] = []
        lines = record.read_bytes().splitlines(keepends=True)
        for line in lines[1:]:
            event = json.loads(line)
            kinds[event["event"]] = kinds.get(event["event"], 0) + len(line)
            if isinstance(event.get("time"), (int, float)):
                times.append(float(event["time"]))
        size = record.stat().st_size
    span = max(times) - min(times) if times else 0.0
    header = len(lines[0]) if lines else 0  # the plan as it ran: once a record, not scaled
    per_hour = header + (size - header) / span * 3600 if span > 0 else 0.0
    return {
        "plan": plan,
        "parts": parts,
        "speed": speed,
        "bytes": size,
        "header_bytes": header,
        "run_s": round(span, 1),
        "sim_s": round(sim_s, 1),
        "mb_per_hour": round(per_hour / 1e6, 1),
        "mb_per_hour_by_kind": {
            k: round(v / span * 3600 / 1e6, 2) for k, v in sorted(kinds.items())
        }
        if span > 0
        else {},
        "wall_s": round(time.perf_counter() - started, 1),
    }


ROWS = ("produced", "caught", "scrapped", "bad_weld", "bad_grasp", "lost_to_stops",
        "operator_interventions", "picks_per_hour")  # fmt: skip


def _percent(entry: dict[str, Any]) -> str:
    produced = entry.get("produced", 0)
    if not produced:
        return "-"
    return f"{100 * (entry.get('caught', 0) + entry.get('scrapped', 0)) / produced:.0f} %"


def _cell(entry: dict[str, Any], row: str) -> str:
    """A row's figure; over several pairs, its mean per pair and (min-max)."""
    spread = entry.get("spread", {}).get(row)
    if spread is None:
        return str(entry.get(row, "-"))
    return f"{spread['mean']:g} ({spread['min']:g}-{spread['max']:g})"


def table_one(figures: dict[str, Any]) -> str:
    """Table I side by side: the paper at Marlin Steel, the paper's plan and ours here (with
    pairs: each figure per pair of trials as mean (min-max) over the pairs).
    """
    columns = [("paper (Marlin)", PAPER), ("paper's plan, sim", figures.get("paper", {})),
               ("ours, sim", figures.get("ours", {}))]  # fmt: skip
    width = 24 if any("spread" in entry for _, entry in columns) else 20
    pairs = max((len(entry.get("pairs", [])) for _, entry in columns), default=0)
    title = f"Table I, {pairs} pairs" if pairs else "Table I"
    lines = [f"{title:24}" + "".join(f"{name:>{width}}" for name, _ in columns)]
    for row in ROWS:
        cells = [_cell(entry, row) for _, entry in columns]
        lines.append(f"{row:24}" + "".join(f"{c:>{width}}" for c in cells))
    handled = [f"{_percent(PAPER)} ({PAPER_PROJECTED} % proj.)"]
    handled += [_percent(entry) for _, entry in columns[1:]]
    lines.append(f"{'handled':24}" + "".join(f"{c:>{width}}" for c in handled))
    return "\n".join(lines)
