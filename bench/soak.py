"""Soak: tend the simulated wire bender for hours and watch memory, stalls and tick overruns.

Runs our tending plan (``resources/examples/tending.costar.json``; the paper's until ours
exists, or ``--plan paper``) on the ``tending`` scene for ``--hours`` simulated hours (the
bender gets as many parts as fit), in lockstep and paced as ``bench/casestudies.py`` runs
tending, with the operator model answering the paper's plan. It measures:

- memory: the process's resident set (RSS) sampled over the run; growth is the end against
  the RSS once warmed up (after the first 5 % of the simulated time: caches, first renders).
- stalls: spans of more than ``--stall-s`` wall seconds in which the simulated time or the
  engine's ticks did not advance.
- tick overruns: ticks that took longer than the executor's period (``Executor.period``;
  each tick is timed by wrapping the tree's ``tick``), and late ticks (begun more than two
  periods after the one before: the engine thread did not get its turn).

Goals (issue 13): growth under 5 %, no stall. Run from the repository root::

    .venv/bin/python bench/soak.py [--hours 4] [--seed 2000] [--plan ours] [--json]

JSON (one object at the end): ``{"plan": "ours", "hours": 4.0, "sim_s": ..., "wall_s": ...,
"rss_mb": {"first", "warm", "end", "max"}, "growth_pct": ..., "samples": [[sim_s, rss_mb],
...], "stalls": [...], "ticks": ..., "overruns": ..., "late_ticks": ..., "counters": {...}}``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from bench._tending import (  # noqa: E402
    PLANS,
    RESET_S,
    c_output_to_stderr,
)
from capabilities.sim.scene import default_scene_path  # noqa: E402
from capabilities.sim.session import SimCellSession  # noqa: E402
from capabilities.sim.tending_trial import OperatorModel, TendingTrial, trial_session  # noqa: E402

WARM_FRACTION = 0.05  # of the simulated time: RSS after it is the baseline of growth
PAGE = os.sysconf("SC_PAGE_SIZE")


def rss_mb() -> float:
    """This process's resident set now (MB; Linux /proc)."""
    with open("/proc/self/statm", encoding="ascii") as statm:
        return int(statm.read().split()[1]) * PAGE / 1e6


def soak_scene(folder: Path, hours: float) -> Path:
    """The tending scene with enough parts for ``hours`` of the bender's shortest intervals."""
    data = json.loads(default_scene_path("tending").read_text(encoding="utf-8"))
    bender = data["bender"]
    shortest = bender["interval"] * (1 - bender.get("faults", {}).get("interval_spread", 0.35))
    bender["parts"] = math.ceil(hours * 3600 / shortest) + 1
    path = folder / "tending_soak.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    return path


class TickClock:
    """Times every tick of a tree (wraps its ``tick``): overruns and late starts."""

    def __init__(self, tree: Any, period: float) -> None:
        self.period = period
        self.ticks = self.overruns = self.late = 0
        self.max_tick = self.max_gap = 0.0
        self.last_start = time.perf_counter()
        inner = tree.tick

        def timed() -> Any:
            start = time.perf_counter()
            gap, self.last_start = start - self.last_start, start
            try:
                return inner()
            finally:
                took = time.perf_counter() - start
                self.ticks += 1
                self.overruns += took > period
                self.late += gap > 2 * period
                self.max_tick, self.max_gap = max(self.max_tick, took), max(self.max_gap, gap)

        tree.tick = timed

    def figures(self) -> dict[str, Any]:
        return {"ticks": self.ticks, "tick_period_ms": round(1000 * self.period, 1),
                "overruns": self.overruns, "max_tick_ms": round(1000 * self.max_tick, 1),
                "late_ticks": self.late, "max_gap_ms": round(1000 * self.max_gap, 1)}  # fmt: skip


class Watch:
    """Samples RSS and looks for stalls (no simulated time, no tick) once a wall second."""

    def __init__(self, session: SimCellSession, ticks: TickClock, stall_s: float) -> None:
        self.samples: list[tuple[float, float]] = []
        self.stalls: list[dict[str, Any]] = []
        self._session, self._ticks, self._stall_s = session, ticks, stall_s

    def run(self, done: threading.Event, every: float) -> None:
        sim_at, ticks_at = self._session.clock(), self._ticks.ticks
        sim_moved = ticks_moved = last_sample = time.monotonic()
        while not done.wait(1.0):
            now = time.monotonic()
            sim, ticks = self._session.clock(), self._ticks.ticks
            if sim > sim_at:
                sim_at, sim_moved = sim, now
            if ticks > ticks_at:
                ticks_at, ticks_moved = ticks, now
            for what, since in (("simulated time", sim_moved), ("ticks", ticks_moved)):
                if now - since > self._stall_s and not self._open(what):
                    self.stalls.append({"what": what, "at_sim_s": round(sim, 1), "open": True})
            self._close_ended(now - sim_moved, now - ticks_moved)
            if now - last_sample >= every:
                self.samples.append((round(sim, 1), round(rss_mb(), 1)))
                last_sample = now

    def _open(self, what: str) -> bool:
        return any(s["what"] == what and s["open"] for s in self.stalls)

    def _close_ended(self, sim_still: float, ticks_still: float) -> None:
        for stall in self.stalls:
            still = sim_still if stall["what"] == "simulated time" else ticks_still
            if stall["open"] and still < self._stall_s:
                stall["open"] = False


def _memory(samples: list[tuple[float, float]], sim_s: float) -> dict[str, Any]:
    if not samples:
        return {"rss_mb": {}, "growth_pct": None}
    warm = next((mb for t, mb in samples if t >= WARM_FRACTION * sim_s), samples[0][1])
    end = samples[-1][1]
    rss = {"first": samples[0][1], "warm": warm, "end": end, "max": max(m for _, m in samples)}
    return {"rss_mb": rss, "growth_pct": round(100 * (end - warm) / warm, 2)}


def soak(plan: str, hours: float, seed: int, stall_s: float, sample_s: float) -> dict[str, Any]:
    """Run the soak and return its figures."""
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        scene = soak_scene(Path(folder), hours)
        with trial_session(scene, seed) as s:
            trial = TendingTrial(s, PLANS[plan], OperatorModel(reset_s=RESET_S))
            ticks = TickClock(trial.executor.tree, trial.executor.period)
            watch, done = Watch(s, ticks, stall_s), threading.Event()
            watcher = threading.Thread(target=watch.run, args=(done, sample_s), daemon=True)
            watcher.start()
            try:
                counters = trial.run(until=hours * 3600.0)
            finally:
                done.set()
                watcher.join()
            watch.samples.append((round(s.clock(), 1), round(rss_mb(), 1)))
            sim_s = s.clock() - (s.bender.start_time or 0.0) if s.bender else s.clock()
    figures = {"plan": plan, "hours": hours, "seed": seed, "sim_s": round(sim_s, 1),
               "wall_s": round(time.perf_counter() - started, 1)}  # fmt: skip
    figures |= _memory(watch.samples, sim_s) | {"samples": watch.samples}
    figures |= {"stalls": watch.stalls, "stall_bound_s": stall_s} | ticks.figures()
    return figures | {"counters": counters.as_dict()}


def main(argv: list[str] | None = None) -> int:
    """Tend for ``--hours`` simulated hours; print memory growth, stalls and tick overruns."""
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--hours", type=float, default=4.0, help="simulated hours")
    parser.add_argument("--seed", type=int, default=2000)
    parser.add_argument("--plan", choices=sorted(PLANS), default=None,
                        help="default: ours if it exists, else the paper's")  # fmt: skip
    parser.add_argument("--stall-s", type=float, default=30.0, help="wall seconds that stall")
    parser.add_argument("--sample-s", type=float, default=30.0, help="wall s between samples")
    parser.add_argument("--json", action="store_true", help="print one JSON object at the end")
    args = parser.parse_args(argv)
    plan = args.plan or ("ours" if PLANS["ours"].is_file() else "paper")
    with c_output_to_stderr():
        fig = soak(plan, args.hours, args.seed, args.stall_s, args.sample_s)
    if args.json:
        print(json.dumps(fig))
        return 0
    rss = fig["rss_mb"]
    print(f"soak: {plan}'s plan, {fig['sim_s']:.0f} simulated s in {fig['wall_s']:.0f} wall s")
    print(f"memory: RSS {rss.get('warm')} MB warm -> {rss.get('end')} MB at the end "
          f"({fig['growth_pct']} %), max {rss.get('max')} MB")  # fmt: skip
    print(f"stalls (> {args.stall_s:g} s): {len(fig['stalls'])} {fig['stalls']}")
    print(
        f"ticks: {fig['ticks']}, overruns (> {fig['tick_period_ms']} ms): {fig['overruns']}, "
        f"max {fig['max_tick_ms']} ms; late: {fig['late_ticks']}, max gap {fig['max_gap_ms']} ms"
    )
    print(f"counters: {fig['counters']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
