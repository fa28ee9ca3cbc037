"""Tick cost of our engine against py_trees 2.x, and the executor's wake-up latency.

Builds the four trees of ``bench/trees/trees.json`` in both engines in this process (see
``bench/_bt_trees.py``), checks them against the file's expected counts (:func:`verify`, a
counting pass on an instance of their own, never timed), then times them:

- per_tick trees (T1-T3): one tick of the file's node 0 (no Root above it); ours is followed
  by a reset of node 0 inside the timed loop, because our nodes latch and a finished tree
  must be reset before it runs again (py_trees' composites re-initialise, stopping their
  children, at the start of the next tick, so both pay for a restart);
- until_done tree (T4): tick until SUCCESS (ours: plus the reset after it); total time /
  total visits.

Each figure is the median of several repetitions after a warm-up, with the garbage
collector disabled inside the timed loops.

``recording_tick_ratio``: ticks a second of a running plan (at 50 Hz) with its run record
on (the trace, joints at 10 Hz, two cameras' thumbnails a second) divided by off (goal at
least 0.95); ``recording.flat_out``: the same with the executor ticking as fast as it can
(``bench/_recording.py``). Run from the repository root::

    .venv/bin/python bench/engine_ticks.py [--json] [--trees PATH] [--recording-s 3]
"""

from __future__ import annotations

import argparse
import gc
import json
import queue
import statistics
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._bt_trees import (
    ENGINES,
    BenchError,
    BuiltTree,
    TreeDef,
    default_trees_path,
    load_trees,
    type_name,
)
from bench._recording import recording_tick_ratio
from engine.composites import Sequence
from engine.context import TreeContext
from engine.executor import Executor
from engine.leaves import OperationLeaf
from engine.node import Node
from engine.operations import Job, OperationCall, OperationKind
from engine.tree import BehaviorTree, Root

__all__ = ["verify", "measure_tree", "measure_wakeup", "run_bench", "main"]


# ---------------------------------------------------------------------- verification


def _shape(root: Any) -> tuple[int, Counter[str], int]:
    """(node count, node types, max depth) reached from ``root``; iterative for deep trees."""
    count, types, depth = 0, Counter[str](), 0
    stack = [(root, 0)]
    while stack:
        node, level = stack.pop()
        count += 1
        types[type_name(node)] += 1
        depth = max(depth, level)
        stack.extend((child, level + 1) for child in node.children)
    return count, types, depth


def _install_counter(built: BuiltTree) -> list[int]:
    """Wrap every node's ``tick`` so that each execution adds one visit to the returned counter.

    Both engines call ``child.tick()`` through the instance, so an instance attribute wins
    over the class's method. py_trees' ``tick`` is a generator that ``stop()`` also creates
    (without running it) to reset its iterator: there a visit is counted when the generator
    starts running. Only for the counting pass: it slows the tree down.
    """
    visits = [0]
    for node in built.nodes:
        original = node.tick
        if built.engine == "py_trees":

            def counted_gen(original: Callable[[], Any] = original) -> Any:
                visits[0] += 1
                yield from original()

            node.tick = counted_gen
        else:

            def counted(original: Callable[[], Any] = original) -> Any:
                visits[0] += 1
                return original()

            node.tick = counted
    return visits


def _check(tree: TreeDef, engine: str, what: str, got: object, want: object) -> None:
    if got != want:
        raise BenchError(
            f"{tree.id} ({tree.key}), {engine}: {what} is {got}, the file expects {want}"
        )


def verify(tree: TreeDef, built: BuiltTree) -> None:
    """Check a freshly built tree against the file's ``expected`` block (not timed).

    Checks the node count, node types and depth, then counts visits: per_tick trees over a
    few ticks (each from a fresh run) and through ``loop``; until_done trees over two
    complete runs (the second after ``restart``) and through ``run``. Raises BenchError.
    """
    want, name = tree.expected, built.engine
    count, types, depth = _shape(built.root)
    _check(tree, name, "node count", count, want["node_count"])
    _check(tree, name, "node types", dict(types), want["node_types"])
    _check(tree, name, "max depth", depth, want["max_depth"])
    visits = _install_counter(built)
    if tree.measure == "per_tick":
        for _ in range(3):
            visits[0] = 0
            _check(tree, name, "root status", built.tick_once(), want["root_status"])
            _check(tree, name, "visits per tick", visits[0], want["visits_per_tick"])
            built.restart()
        visits[0] = 0
        built.loop(4)
        _check(tree, name, "visits in 4 timed-loop ticks", visits[0], 4 * want["visits_per_tick"])
    elif tree.measure == "until_done":
        for _ in range(2):
            _verify_run(tree, built, visits)
        visits[0] = 0
        _check(tree, name, "ticks of the timed run", built.run(), want["ticks_to_complete"])
        _check(tree, name, "visits of the timed run", visits[0], want["visits_total"])
    else:
        raise BenchError(f"tree {tree.id}: unknown measure {tree.measure!r}")


def _verify_run(tree: TreeDef, built: BuiltTree, visits: list[int]) -> None:
    want = tree.expected
    limit = 10 * int(want["ticks_to_complete"])
    visits[0] = ticks = 0
    status = "RUNNING"
    while status == "RUNNING" and ticks < limit:
        status = built.tick_once()
        ticks += 1
    _check(tree, built.engine, "root status", status, want["root_status"])
    _check(tree, built.engine, "ticks to complete", ticks, want["ticks_to_complete"])
    _check(tree, built.engine, "visits in total", visits[0], want["visits_total"])
    built.restart()


# ---------------------------------------------------------------------- timing


@contextmanager
def _gc_off() -> Iterator[None]:
    """No garbage collection inside a timed region (a collection would land in one sample)."""
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _visits_per_sample(tree: TreeDef) -> int:
    """Visits in one sample: one tick (per_tick) or one complete run (until_done)."""
    if tree.measure == "per_tick":
        return int(tree.expected["visits_per_tick"])
    return int(tree.expected["visits_total"])


def _sampler(tree: TreeDef, built: BuiltTree) -> Callable[[int], None]:
    """``sample(n)`` runs n samples of the tree's measure."""
    if tree.measure == "per_tick":
        return built.loop
    run = built.run

    def runs(n: int) -> None:
        for _ in range(n):
            run()

    return runs


def _calibrate(sample: Callable[[int], None], min_time: float) -> int:
    """Warm up, and return a sample count that takes at least ``min_time`` seconds."""
    n = 1
    while True:
        start = time.perf_counter_ns()
        sample(n)
        if time.perf_counter_ns() - start >= min_time * 1e9:
            return n
        n *= 2


def measure_tree(
    tree: TreeDef, builts: list[BuiltTree], reps: int = 7, min_time: float = 0.05
) -> dict[str, float]:
    """Median nanoseconds per node visited, per engine, over ``reps`` repetitions.

    A warm-up sizes each engine's repetition to last at least ``min_time`` seconds. The
    engines take turns repetition by repetition, so that load from other processes falls
    on both alike.
    """
    samplers = [_sampler(tree, built) for built in builts]
    visits = _visits_per_sample(tree)
    clock = time.perf_counter_ns
    per_visit: list[list[float]] = [[] for _ in builts]
    with _gc_off():
        counts = [_calibrate(sample, min_time) for sample in samplers]
        for _ in range(reps):
            for sample, n, results in zip(samplers, counts, per_visit, strict=True):
                start = clock()
                sample(n)
                results.append((clock() - start) / (n * visits))
    return {b.engine: statistics.median(r) for b, r in zip(builts, per_visit, strict=True)}


# ---------------------------------------------------------------------- wake-up latency


class _AsyncStart:
    """An action whose job another thread finishes; hands each job to that thread."""

    def __init__(self, jobs: queue.Queue[Job]) -> None:
        self._jobs = jobs

    def start(self, call: OperationCall) -> Job:
        job = Job()
        self._jobs.put(job)
        return job


class _Stamp:
    """An action that notes when it started and succeeds at once."""

    def __init__(self, stamps: list[int]) -> None:
        self._stamps = stamps

    def start(self, call: OperationCall) -> Job:
        self._stamps.append(time.perf_counter_ns())
        return Job.done()


def _finisher(jobs: queue.Queue[Job], finished: list[int], runs: int, pause: float) -> None:
    """Finish each job once the engine is idle again, noting when succeed() was called."""
    for _ in range(runs):
        job = jobs.get(timeout=10.0)
        time.sleep(pause)  # let the engine go back to waiting for its next period
        finished.append(time.perf_counter_ns())
        job.succeed()


def measure_wakeup(runs: int = 300, rate_hz: float = 1.0, pause: float = 0.002) -> list[float]:
    """Wake-up latencies in microseconds: an asynchronous leaf finishing -> next leaf started.

    One executor at ``rate_hz`` (slow, so that a tick by period never hides a missed wake-up)
    runs Root(once) -> Sequence[async_0, stamp_0, async_1, stamp_1, ...]. Another thread
    finishes each async job ``pause`` seconds after it started; a latency is the time from
    that ``job.succeed()`` call to the start() of the stamp leaf after it.
    """
    ctx = TreeContext()
    jobs: queue.Queue[Job] = queue.Queue()
    finished: list[int] = []
    stamps: list[int] = []
    leaves: list[Node] = []
    for i in range(runs):
        leaves.append(
            OperationLeaf(ctx, f"a{i}", f"async_{i}", OperationKind.ACTION, _AsyncStart(jobs))
        )
        leaves.append(
            OperationLeaf(ctx, f"s{i}", f"stamp_{i}", OperationKind.ACTION, _Stamp(stamps))
        )
    sequence = Sequence(ctx, "seq", "chain")
    sequence.set_children(leaves)
    root = Root(ctx, "root")
    root.set_children([sequence])
    executor = Executor(BehaviorTree(root, ctx), rate_hz=rate_hz)
    helper = threading.Thread(target=_finisher, args=(jobs, finished, runs, pause), daemon=True)
    with _gc_off():
        helper.start()
        executor.start()
        result = executor.wait(timeout=runs * (pause + 0.5) + 10.0)
    helper.join(1.0)
    if result is None or result.status.value != "SUCCESS" or len(stamps) != runs:
        executor.stop("bench timeout")
        raise BenchError(f"wake-up run did not finish: {result}, {len(stamps)} of {runs} stamps")
    return [(s - f) / 1000.0 for s, f in zip(stamps, finished, strict=True)]


def _percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, round(fraction * (len(ordered) - 1))))
    return ordered[index]


# ---------------------------------------------------------------------- the whole bench


def run_bench(
    trees_path: Path,
    reps: int = 7,
    min_time: float = 0.05,
    wakeup_runs: int = 300,
    recording_s: float = 3.0,
) -> dict[str, Any]:
    """Verify and time every tree in both engines, then measure wake-up latency.

    Returns the ``--json`` object: ``{"trees": {id: {"ours_ns", "py_trees_ns", "ratio"}},
    "wakeup_median_us", "wakeup_p99_us", "recording_tick_ratio", "recording": {...}}``
    (``recording_s`` 0: no recording figures). Raises BenchError when a tree does not match
    the file.
    """
    trees = load_trees(trees_path)
    report: dict[str, Any] = {"trees": {}}
    for tree in trees:
        for _, build in ENGINES:
            verify(tree, build(tree))  # counting pass, on an instance of its own
        medians = measure_tree(tree, [build(tree) for _, build in ENGINES], reps, min_time)
        figures = {f"{name}_ns": round(ns, 1) for name, ns in medians.items()}
        figures["ratio"] = round(figures["ours_ns"] / figures["py_trees_ns"], 4)
        report["trees"][tree.id] = figures
    latencies = measure_wakeup(wakeup_runs)
    report["wakeup_median_us"] = round(statistics.median(latencies), 1)
    report["wakeup_p99_us"] = round(_percentile(latencies, 0.99), 1)
    if recording_s > 0:
        recording = recording_tick_ratio(recording_s)
        report["recording_tick_ratio"] = recording.pop("recording_tick_ratio")
        report["recording"] = recording
    return report


def _print_table(trees: list[TreeDef], report: dict[str, Any]) -> None:
    print(f"{'tree':<14}{'measure':<12}{'ours ns/visit':>15}{'py_trees ns/visit':>19}{'ratio':>9}")
    for tree in trees:
        row = report["trees"][tree.id]
        print(
            f"{tree.id + ' ' + tree.key:<14}{tree.measure:<12}{row['ours_ns']:>15.1f}"
            f"{row['py_trees_ns']:>19.1f}{row['ratio']:>9.3f}"
        )
    print(
        f"wake-up latency (job.succeed() -> next leaf start): median "
        f"{report['wakeup_median_us']:.1f} us, p99 {report['wakeup_p99_us']:.1f} us"
    )
    print("(ours: tick + reset of node 0; gc disabled while timing; median of repetitions)")
    if "recording_tick_ratio" in report:
        print(f"recording_tick_ratio {report['recording_tick_ratio']:.3f} (goal >= 0.95)")
        for name in ("at_plan_rate", "flat_out"):
            rec = report["recording"][name]
            print(
                f"  {name} ({rec['rate_hz']:g} Hz asked): ratio {rec['ratio']:.3f}, "
                f"{rec['ticks_per_s_recording']} ticks/s recorded, "
                f"{rec['ticks_per_s_not_recording']} not, "
                f"{rec['record_bytes_per_s']} bytes/s of record"
            )


def main(argv: list[str] | None = None) -> int:
    """Command line: prints a table, or with ``--json`` one JSON object."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", type=Path, default=default_trees_path(), help="trees.json")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--reps", type=int, default=7, help="timed repetitions per tree")
    parser.add_argument("--min-time", type=float, default=0.05, help="seconds per repetition")
    parser.add_argument("--wakeup-runs", type=int, default=300, help="wake-up samples")
    parser.add_argument("--recording-s", type=float, default=3.0,
                        help="seconds of each run with the record on and off (0: none)")  # fmt: skip
    args = parser.parse_args(argv)
    try:
        report = run_bench(args.trees, args.reps, args.min_time, args.wakeup_runs, args.recording_s)
    except BenchError as exc:
        print(f"engine_ticks: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(report))
    else:
        _print_table(load_trees(args.trees), report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
