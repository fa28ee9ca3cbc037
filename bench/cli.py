"""Start-up of the ``costar`` commands that need no cell, beside ``python -c pass``.

For each command (``validate --cell none``, ``import-xml``, ``export-xml``, ``examples``,
``ops --cell none``, ``trace show``) and, as the peer in the same run, ``python -c pass``:
the wall time of a whole process (median of ``--runs``), its CPU time (user + system, median:
steadier than the wall time when other processes load the machine) and its peak resident
memory (``ru_maxrss`` of that child), each with its ratio to the peer, and whether the
command meets the goal of issue 23 (at most 0.5 s and 120 MB).

The runs take turns command by command, so that load from other processes hits all alike;
one untimed run of each comes first. The children import this repository's code
(``PYTHONPATH``) and, as an installed application does, read compiled bytecode: it is kept in
a temporary folder (``-X pycache_prefix``), so nothing is written into the repository;
``--compile`` measures starts that compile every module instead (``PYTHONDONTWRITEBYTECODE``).

Run from the repository root::

    .venv/bin/python bench/cli.py [--runs 5] [--compile] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

__all__ = ["GOAL_RSS_MB", "GOAL_WALL_S", "PEER", "commands", "main", "measure"]

REPO_ROOT = Path(__file__).resolve().parents[1]
GOAL_WALL_S = 0.5
GOAL_RSS_MB = 120.0
PEER = "python -c pass"
PLAN = "example:nodes/selector"


def commands(scratch: Path) -> dict[str, list[str]]:
    """Name -> the arguments after the interpreter; files they read are made in ``scratch``."""
    cli = ["-m", "capabilities.cli"]
    return {
        PEER: ["-c", "pass"],
        "validate --cell none": [*cli, "validate", PLAN, "--cell", "none"],
        "import-xml": [*cli, "import-xml", str(scratch / "plan.xml"), str(scratch / "in.json")],
        "export-xml": [*cli, "export-xml", PLAN, str(scratch / "out.xml")],
        "examples": [*cli, "examples"],
        "ops --cell none": [*cli, "ops", "--cell", "none"],
        "trace show": [*cli, "trace", "show", str(scratch / "plan.trace.jsonl")],
    }


def _prepare(scratch: Path, python: list[str], env: dict[str, str]) -> None:
    """The XML that import-xml reads and a small trace (a run of the plan on no cell)."""
    cli = [*python, "-m", "capabilities.cli"]
    for argv in (
        ["export-xml", PLAN, str(scratch / "plan.xml")],
        ["run", PLAN, "--cell", "none", "--trace", str(scratch / "plan.trace.jsonl")],
    ):
        subprocess.run([*cli, *argv], env=env, check=True, capture_output=True, timeout=120)


def _run_once(argv: list[str], env: dict[str, str]) -> tuple[float, float, float]:
    """(wall s, CPU s, peak RSS MB) of one child process."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=REPO_ROOT
    )
    assert proc.stderr is not None
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    proc.stderr.close()
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {proc.returncode}: {err.decode()[-500:]}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024  # KB on Linux


def measure(runs: int = 5, compile_each_time: bool = False) -> dict[str, Any]:
    """The figures of every command (see the module's docstring)."""
    with tempfile.TemporaryDirectory(prefix="costar-bench-cli-") as folder:
        scratch = Path(folder)
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO_ROOT), env.get("PYTHONPATH")]))
        python = [sys.executable]
        if compile_each_time:
            env["PYTHONDONTWRITEBYTECODE"] = "1"
        else:
            env.pop("PYTHONDONTWRITEBYTECODE", None)
            python += ["-X", f"pycache_prefix={scratch / 'pycache'}"]
        _prepare(scratch, python, env)
        todo = {name: [*python, *args] for name, args in commands(scratch).items()}
        samples: dict[str, list[tuple[float, float, float]]] = {name: [] for name in todo}
        for argv in todo.values():  # warm-up: bytecode written, files in the page cache
            _run_once(argv, env)
        for _ in range(runs):
            for name, argv in todo.items():
                samples[name].append(_run_once(argv, env))
    figures: dict[str, dict[str, Any]] = {}
    for name, got in samples.items():
        wall = statistics.median(s[0] for s in got)
        cpu = statistics.median(s[1] for s in got)
        rss = max(s[2] for s in got)
        figures[name] = {"wall_s": round(wall, 4), "cpu_s": round(cpu, 4), "rss_mb": round(rss, 1)}
    peer = figures[PEER]
    for name, fig in figures.items():
        fig["wall_ratio"] = round(fig["wall_s"] / peer["wall_s"], 2)
        fig["cpu_ratio"] = round(fig["cpu_s"] / max(peer["cpu_s"], 1e-6), 2)
        fig["rss_ratio"] = round(fig["rss_mb"] / peer["rss_mb"], 2)
        if name != PEER:
            fig["meets_goal"] = fig["wall_s"] <= GOAL_WALL_S and fig["rss_mb"] <= GOAL_RSS_MB
            # The same with the CPU time for the wall time: what a quiet machine would show.
            fig["meets_goal_cpu"] = fig["cpu_s"] <= GOAL_WALL_S and fig["rss_mb"] <= GOAL_RSS_MB
    return {
        "runs": runs,
        "bytecode_cached": not compile_each_time,
        "goal": {"wall_s": GOAL_WALL_S, "rss_mb": GOAL_RSS_MB},
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "commands": figures,
    }


def main(argv: list[str] | None = None) -> int:
    """Time the start-up of each command against ``python -c pass``; print the table
    (``--json``: also one JSON object).
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="timed runs per command (median)")
    parser.add_argument(
        "--compile", action="store_true", help="no bytecode cache: every start compiles"
    )
    parser.add_argument("--json", action="store_true", help="end with one JSON object")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs must be 1 or more")
    result = measure(args.runs, args.compile)
    goal = f"goal: <= {GOAL_WALL_S} s (wall) and <= {GOAL_RSS_MB:.0f} MB"
    print(f"{'command':22} {'wall s':>7} {'x peer':>7} {'CPU s':>7} {'x peer':>7} "
          f"{'RSS MB':>7} {'x peer':>7}  {goal}")  # fmt: skip
    for name, fig in result["commands"].items():
        verdict = "(peer)"
        if name != PEER:
            verdict = "meets" if fig["meets_goal"] else "misses"
            verdict += f"; in CPU time {'meets' if fig['meets_goal_cpu'] else 'misses'}"
        print(f"{name:22} {fig['wall_s']:7.3f} {fig['wall_ratio']:7.2f} {fig['cpu_s']:7.3f} "
              f"{fig['cpu_ratio']:7.2f} {fig['rss_mb']:7.1f} {fig['rss_ratio']:7.2f}  "
              f"{verdict}")  # fmt: skip
    cached = "cached bytecode" if result["bytecode_cached"] else "compiling every start"
    print(f"{result['runs']} runs each, {cached}, load average {result['load_average']}")
    if args.json:
        print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
