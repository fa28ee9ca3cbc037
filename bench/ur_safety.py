"""Stop means stop, and every fault is recovered from: trials against the loopback UR emulator.

    .venv/bin/python bench/ur_safety.py [--trials 20] [--load 2] [--only stops|recoveries]
                                        [--hosts 127.0.0.240] [--json]

stops: ``costar run`` of a plan whose second move turns the base joint 2.4 rad; one second
into that move the run gets SIGTERM, SIGINT, SIGHUP or SIGKILL. Per signal: how long until the
controller reports the arm not moving (``stop_s``: median and max, polled every 10 ms through
the emulator's control pipe), whether its joints then stand still (no joint moves more than
0.1 mrad over the next 0.5 s), and how many of the trials stopped within 0.5 s. SIGKILL is
stopped by the control script's watchdog alone (the program has no chance to say anything).

recoveries: a plan of moves runs on a UR cell through the executor (in this process); during
a move the emulator injects a fault, and the operator clears it as on a real cell:

- protective_stop: the pendant's unlock (dashboard ``unlock protective stop``);
- emergency_stop: release the button, then power on and brake release (dashboard);
- power_off: power on and brake release;
- kill_script: the Instructor's "Restart control script" (``URCellSession.clear``);
- disconnect: nothing (every socket dropped; the cell reconnects by itself).

A trial succeeds when the plan then ends in SUCCESS with the arm at its last target. Per
fault: successes of trials and the failures' reasons.

``--load N`` runs N busy processes beside the trials (a loaded machine). Figures only, never
pass/fail; ``--json`` prints one JSON object at the end.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from capabilities.base import CapabilityRegistry  # noqa: E402
from capabilities.cells import open_cell  # noqa: E402
from capabilities.faults import hold_check  # noqa: E402
from capabilities.ur_emulator.process import EmulatorProcess  # noqa: E402
from engine.build import build_tree  # noqa: E402
from engine.executor import Executor  # noqa: E402
from engine.files import save_plan  # noqa: E402
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec  # noqa: E402
from engine.status import SUCCESS  # noqa: E402
from engine.types import JointConfig, ParamType  # noqa: E402

HOME = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)
SIGNALS = ("SIGTERM", "SIGINT", "SIGHUP", "SIGKILL")
FAULTS = tuple(
    os.environ.get(
        "FAULTS", "protective_stop,emergency_stop,power_off,kill_script,disconnect"
    ).split(",")
)
STILL_RAD = 1e-4


def moves_plan(offsets: tuple[float, ...], speed: float) -> PlanSpec:
    """A Sequence of joint moves of the base joint to HOME + each offset."""
    moves = [
        NodeSpec(
            NodeKind.OPERATION,
            f"move {i}",
            op="motion.move_joints",
            params={
                "target": Binding.fixed(
                    JointConfig((HOME[0] + offset, *HOME[1:])), ParamType.JOINTS
                ),
                "speed": Binding.fixed(speed, ParamType.NUMBER),
            },
        )
        for i, offset in enumerate(offsets)
    ]
    return PlanSpec(NodeSpec(NodeKind.SEQUENCE, "moves", children=moves), "ur moves")


@contextmanager
def busy_load(jobs: int) -> Iterator[None]:
    """``jobs`` processes that spin (a loaded machine) for the time of the block."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(jobs)]
    try:
        yield
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()


def wait_for(predicate: Callable[[], bool], timeout: float, step: float = 0.01) -> bool:
    """True once ``predicate()`` holds, polled every ``step`` s; its last answer after
    ``timeout`` s.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return predicate()


# ---------------------------------------------------------------------- stops


def stop_trial(emulator: EmulatorProcess, cell_file: Path, plan_file: Path, sig: str) -> dict:
    """One ``costar run``, signalled one second into its long move."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    run = subprocess.Popen(
        [sys.executable, "-m", "capabilities.cli", "run", str(plan_file), "--cell",
         str(cell_file), "--timeout", "60"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=str(ROOT),
    )  # fmt: skip
    try:
        # The first move takes the arm home (from where the last trial stopped it), the
        # second turns the base joint: wait until the arm was home, then well into the turn.
        home = wait_for(lambda: abs(emulator.state()["q"][0] - HOME[0]) < 0.02, 120)
        started = home and wait_for(lambda: emulator.state()["q"][0] > HOME[0] + 0.1, 60)
        if not started:
            return {"ok": False, "why": "the long move never started"}
        time.sleep(1.0)
        run.send_signal(getattr(signal, sig))
        sent = time.monotonic()
        stopped = wait_for(lambda: not emulator.state()["moving"], 5.0)
        stop_s = time.monotonic() - sent
        q0 = emulator.state()["q"]
        time.sleep(0.5)
        q1 = emulator.state()["q"]
        still = max(abs(a - b) for a, b in zip(q0, q1, strict=True)) <= STILL_RAD
        return {"ok": stopped and still, "stop_s": stop_s, "still": still, "stopped": stopped}
    finally:
        if run.poll() is None:
            run.kill()
        run.communicate(timeout=30)


def measure_stops(host: str, trials: int, out: Any) -> dict[str, Any]:
    """Per stop signal: how often and how fast ``trials`` runs stopped the moving arm."""
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="costar-stops-") as scratch:
        cell_file, plan_file = Path(scratch, "emu.cell.json"), Path(scratch, "p.costar.json")
        save_plan(moves_plan((0.0, 2.4), 0.6), plan_file)
        with EmulatorProcess(host=host, write_cell=cell_file, unlock_delay=0.0) as emulator:
            for sig in SIGNALS:
                rows = [stop_trial(emulator, cell_file, plan_file, sig) for _ in range(trials)]
                times = [r["stop_s"] for r in rows if "stop_s" in r]
                results[sig] = {
                    "trials": trials,
                    "stopped_within_0_5_s": sum(1 for r in rows if r["ok"] and r["stop_s"] <= 0.5),
                    "standing_still": sum(1 for r in rows if r.get("still")),
                    "stop_s_median": round(statistics.median(times), 3) if times else None,
                    "stop_s_max": round(max(times), 3) if times else None,
                    "failures": [r.get("why", r) for r in rows if not r["ok"]][:5],
                }
                print(f"{sig:8} {results[sig]}", file=out, flush=True)
    return results


# ---------------------------------------------------------------------- recoveries


def _clear(fault: str, emulator: EmulatorProcess, cell: Any) -> None:
    """What the operator does once the fault is there."""
    import dashboard_client

    if fault == "kill_script":
        cell.clear()
        return
    if fault == "disconnect":
        return
    pendant = dashboard_client.DashboardClient(emulator.host)
    pendant.connect()
    try:
        if fault == "protective_stop":
            pendant.closeSafetyPopup()
            wait_for(lambda: _unlocked(pendant), 10, step=0.2)  # refused until unlock_delay
        else:
            if fault == "emergency_stop":
                emulator.release_emergency_stop()
            pendant.powerOn()
            pendant.brakeRelease()
    finally:
        pendant.disconnect()


def _unlocked(pendant: Any) -> bool:
    try:
        pendant.unlockProtectiveStop()
    except RuntimeError:
        return False
    return True


def recovery_trial(emulator: EmulatorProcess, cell_file: Path, fault: str) -> dict:
    """One run with ``fault`` injected mid-move: whether the cell held and the run went on after
    the recovery.
    """
    plan = moves_plan((0.3, -0.6, 0.2), 0.5)
    held: list[str] = []
    with open_cell(str(cell_file)) as cell:
        tree = build_tree(plan, CapabilityRegistry(cell=cell), clock=cell.clock)
        executor = Executor(tree, 20.0, [], plan_name=plan.name, hold=hold_check(cell))
        executor.start()
        try:
            second = plan.tree.children[1].id  # type: ignore[union-attr]
            if not wait_for(lambda: tree.nodes[second].status.value == "RUNNING", 30):
                return {"ok": False, "why": "the second move never ran"}
            wait_for(lambda: emulator.state()["moving"], 5)
            time.sleep(0.3)
            emulator.command(fault)
            if not wait_for(lambda: bool(executor.held), 30):
                return {"ok": False, "why": f"{fault} did not hold the run"}
            held.append(executor.held)
            _clear(fault, emulator, cell)
            result = executor.wait(90)
            if result is None:
                return {"ok": False, "why": f"not finished 90 s after the clear ({executor.held})"}
            q = emulator.state()["q"]
            at_target = abs(q[0] - (HOME[0] + 0.2)) < 0.01
            ok = result.status is SUCCESS and at_target
            leaves = "; ".join(f"{n.name}: {n.message}" for n in tree.iterate() if n.message)
            why = "" if ok else f"{result.status.value} at q0={q[0]:.3f}: {leaves}"
            return {"ok": ok, "why": why, "held": held}
        finally:
            executor.stop()
            executor.wait(10)


def measure_recoveries(host: str, trials: int, out: Any) -> dict[str, Any]:
    """Per fault: how many of ``trials`` runs recovered, each on a fresh emulator."""
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="costar-faults-") as scratch:
        cell_file = Path(scratch, "emu.cell.json")
        for fault in FAULTS:
            rows = []
            for _ in range(trials):
                # A fresh controller per trial: faults leave no trace for the next one.
                with EmulatorProcess(host=host, write_cell=cell_file, unlock_delay=0.5) as emu:
                    rows.append(recovery_trial(emu, cell_file, fault))
            failures = [r["why"] for r in rows if not r["ok"]]
            results[fault] = {"trials": trials, "recovered": trials - len(failures),
                              "failures": failures[:5]}  # fmt: skip
            print(f"{fault:16} {results[fault]}", file=out, flush=True)
    return results


def main(argv: list[str] | None = None) -> int:
    """Run the stop and recovery trials against the emulator; print the report."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[1])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--load", type=int, default=0, help="busy processes beside the trials")
    parser.add_argument("--only", choices=("stops", "recoveries"))
    parser.add_argument("--host", default="127.0.0.240", help="the emulator's loopback address")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--verbose", action="store_true", help="log the UR cell's messages")
    args = parser.parse_args(argv)
    if args.verbose:
        import logging

        logging.basicConfig(
            level=logging.INFO, format="%(relativeCreated)8.0f %(name)s %(message)s"
        )
    report: dict[str, Any] = {"trials": args.trials, "load": args.load,
                              "cores": multiprocessing.cpu_count()}  # fmt: skip
    with busy_load(args.load):
        if args.only in (None, "stops"):
            report["stops"] = measure_stops(args.host, args.trials, sys.stdout)
        if args.only in (None, "recoveries"):
            report["recoveries"] = measure_recoveries(args.host, args.trials, sys.stdout)
    if args.json:
        print(json.dumps(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
