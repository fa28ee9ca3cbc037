"""Teaching by hand on the simulated cell (real time, as a worker uses it).

Figures, through the Instructor's RobotTeacher (the Move panel's and the 3D scene's path):

- ``drag_lag_mm`` / ``drag_lag_max_mm``: while a hand drags the tool gizmo 10 cm at 10 cm/s
  (a new target 30 times a second), how far the TCP is behind the newest target, mean and
  worst; ``drag_settle_ms``: from letting go until the TCP is within 1 mm of it.
- the same three with ``_ik`` for the peer path: a cell without a freedrive drag, where the
  teacher follows through IK and joint moves (each new target preempts the last move).
- ``drag_commands_per_s``: drag targets the worker passed to the cell per second (the newest
  wins; older ones are dropped, never queued).
- ``jog_step_error_mm`` / ``jog_step_ms``: five 10 mm steps up (Move panel at 25 %): the worst
  difference between the step and how far the arm's reported TCP moved, and the mean time
  from the click to the end of the move.
- ``figure3_actions`` / ``tending_setup_actions``: the user's actions of the suite's two
  scripted builds by hand, counted as the suite counts them (tests/instructor_app/
  gui_driver.py's CountingBot): Figure 3 from an empty plan (test_end_to_end.py) and our
  tending plan set up from the library (test_tending_setup.py). The builds are those tests
  themselves, run here by pytest in a child process (their scripts, not a copy); each
  test records its count with ``record_property`` before it checks it.

Run from the repository root (under a display, e.g. ``xvfb-run -a``)::

    .venv/bin/python bench/teach.py [--json] [--actions-only]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from PySide6.QtCore import QCoreApplication, Qt

from capabilities.base import CapabilityRegistry
from capabilities.sim.session import SimCellSession
from engine.types import Pose
from instructor_app.runtime.teach import RobotTeacher

_ROOT = Path(__file__).resolve().parents[1]
# The scripted builds whose counts are reported: test node id -> the figure it records.
BUILDS = {
    "tests/instructor_app/test_end_to_end.py::"
    "test_figure3_built_by_hand_with_grasp_counted_saved_reopened_and_run": "figure3_actions",
    "tests/instructor_app/test_tending_setup.py::"
    "test_our_tending_plan_set_up_from_the_library_by_hand_as_on_site": "tending_setup_actions",
}
_RATE_HZ = 30.0
_SPEED = 0.10  # m/s of the hand
_LENGTH = 0.10  # m


class _NoDragCell:
    """The simulated cell without its freedrive interface: the IK path of the teacher."""

    def __init__(self, cell: SimCellSession) -> None:
        self._cell = cell

    def interfaces(self) -> dict[str, Any]:
        return {k: v for k, v in self._cell.interfaces().items() if k != "freedrive"}

    def clock(self) -> float:
        return self._cell.clock()


def _expect(teacher: RobotTeacher, what: str) -> threading.Event:
    """An event set when the teacher says ``what`` ended (connect before the command)."""
    done = threading.Event()

    def seen(name: str, _problem: str) -> None:
        if name == what:
            done.set()

    teacher.finished.connect(seen, Qt.ConnectionType.DirectConnection)  # no event loop here
    return done


def measure_drag(teacher: RobotTeacher, arm: Any, suffix: str) -> dict[str, Any]:
    """Drag the gizmo along y and back to where it started; the TCP's lag behind it."""
    start = arm.tcp_pose()
    calls = 0
    drive = teacher.interface("freedrive")
    if drive is not None:  # count what reaches the cell
        original = drive.freedrive_drag_to

        def counted(pose: Pose) -> Any:
            nonlocal calls
            calls += 1
            return original(pose)

        drive.freedrive_drag_to = counted
    lags: list[float] = []
    steps = int(_LENGTH / _SPEED * _RATE_HZ)
    t0 = time.perf_counter()
    target = start
    for k in range(1, steps + 1):
        y = start.position[1] + _LENGTH * k / steps
        target = Pose((start.position[0], y, start.position[2]), start.orientation)
        teacher.drag_to(target)
        time.sleep(max(0.0, t0 + k / _RATE_HZ - time.perf_counter()))
        lags.append(math.dist(arm.tcp_pose().position, target.position) * 1000)
    dragged = time.perf_counter() - t0
    released = time.perf_counter()
    while math.dist(arm.tcp_pose().position, target.position) > 0.001:
        if time.perf_counter() - released > 10:
            break
        time.sleep(0.005)
    settle = (time.perf_counter() - released) * 1000
    ended = _expect(teacher, "drag end")
    teacher.end_drag()
    ended.wait(30)
    if drive is not None:
        del drive.freedrive_drag_to  # the class's method again
    figures = {
        f"drag_lag_mm{suffix}": round(statistics.fmean(lags), 1),
        f"drag_lag_max_mm{suffix}": round(max(lags), 1),
        f"drag_settle_ms{suffix}": round(settle),
    }
    if drive is not None:
        figures["drag_commands_per_s"] = round(calls / dragged, 1)
    return figures


def measure_jog_steps(teacher: RobotTeacher, arm: Any) -> dict[str, Any]:
    """The worst error (mm) and mean time (ms) of five 10 mm jog steps along the base's z."""
    errors, times = [], []
    for _ in range(5):
        before = arm.tcp_pose().position[2]
        t0 = time.perf_counter()
        done = _expect(teacher, "jog base z")
        teacher.jog_step("base", "z", 0.010)
        done.wait(30)
        times.append((time.perf_counter() - t0) * 1000)
        errors.append(abs(arm.tcp_pose().position[2] - before - 0.010) * 1000)
    return {
        "jog_step_error_mm": round(max(errors), 3),
        "jog_step_ms": round(statistics.fmean(times)),
    }


def action_counts() -> dict[str, Any]:
    """The user's actions of the suite's scripted builds (``BUILDS``), as their tests count
    them: the tests run in a child pytest whose JUnit report carries each recorded count (a
    build whose test fails after counting still reports; one that never counts reports None).
    """
    with tempfile.TemporaryDirectory() as folder:
        report = Path(folder) / "builds.xml"
        command = [sys.executable, "-m", "pytest", *BUILDS, "-q", "-p", "no:cacheprovider"]
        command += ["-o", "junit_family=xunit2", f"--junitxml={report}"]
        env = {**os.environ, "PYTHONPATH": str(_ROOT)}
        subprocess.run(command, cwd=_ROOT, env=env, stdout=subprocess.DEVNULL, check=False)
        recorded = (
            {prop.get("name"): prop.get("value") for prop in ET.parse(report).iter("property")}
            if report.exists()
            else {}
        )
    return {
        figure: int(recorded[figure]) if recorded.get(figure) else None
        for figure in BUILDS.values()
    }


def measurements() -> dict[str, Any]:
    """Jog and drag figures on the simulated cell, with dragging by the cell and by IK as the
    peer.
    """
    app = QCoreApplication.instance() or QCoreApplication([])
    del app
    out: dict[str, Any] = {}
    with SimCellSession("cup_to_bin", seed=0, speed=1.0) as cell:
        arm = cell.interfaces()["arm"]
        teacher = RobotTeacher(CapabilityRegistry(cell=cell))
        out.update(measure_jog_steps(teacher, arm))
        out.update(measure_drag(teacher, arm, ""))
        teacher.shutdown()
        peer = RobotTeacher(CapabilityRegistry(cell=_NoDragCell(cell)))
        out.update(measure_drag(peer, arm, "_ik"))
        peer.shutdown()
    return out


def main(argv: list[str] | None = None) -> None:
    """Print the teaching figures (``--json``: one JSON object at the end)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object at the end")
    parser.add_argument(
        "--actions-only", action="store_true", help="only the scripted builds' action counts"
    )
    args = parser.parse_args(argv)
    figures = action_counts()  # first: the child process has the cores to itself
    if not args.actions_only:
        figures.update(measurements())
    if args.json:
        print(json.dumps(figures))
    else:
        for key, value in figures.items():
            print(f"{key:24s} {value}")


if __name__ == "__main__":
    main()
