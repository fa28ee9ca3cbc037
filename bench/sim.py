"""Headless speed of the simulated cell.

Figures (all with ``speed=None``, as fast as the machine goes):

- ``physics_steps_per_s``: 240 Hz physics steps per wall second with the robot loaded and
  holding still (pybullet step + the controllers' hooks);
- ``moving_steps_per_s``: the same while the arm runs joint moves;
- ``pick_place_rtf``: real-time factor (simulated s / wall s) of a scripted pick-and-place
  (moveJ + moveL + gripper), and its simulated and wall durations;
- ``start_s``: wall time to build the cell;
- ``camera_fps_320x240`` / ``camera_fps_640x480``: shoulder camera frames per wall second
  (render + depth conversion), in a client of their own;
- ``python_work_ms_*``: wall ms of a perception-like Python workload (many small numpy
  calls, each dropping the GIL for a moment) with the world standing still (``alone``),
  beside the world stepping as fast as it can inside ``SimCell.sharing`` as a session's
  worker pool runs perception (``shared``), and beside it without (``unshared``); the
  ratios are each against ``alone`` in the same run;
- ``cup_to_bin_rtf``: real-time factor of a headless run of the paper's Figure 3 plan
  (resources/examples/cup_to_bin.costar.json) through the engine on the simulated cell.

To add a figure (e.g. camera frames per second), write a ``measure_*(cell) -> dict`` function
and add it to the list that ``measurements()`` returns. Run from the repository root::

    .venv/bin/python bench/sim.py [--json]
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._report import figures_parser, print_figures
from capabilities.sim.cell import SimCell
from capabilities.sim.testing import add_box, down_at, run

Measurement = Callable[[SimCell], dict[str, Any]]


def _steps_per_second(cell: SimCell, wall: float) -> float:
    steps0, t0 = cell.steps(), time.perf_counter()
    time.sleep(wall)
    return (cell.steps() - steps0) / (time.perf_counter() - t0)


def measure_idle_steps(cell: SimCell) -> dict[str, Any]:
    """Physics steps per wall second with the arm holding still."""
    return {"physics_steps_per_s": round(_steps_per_second(cell, 2.0))}


def measure_moving_steps(cell: SimCell) -> dict[str, Any]:
    """Physics steps per wall second while the arm moves back and forth."""
    home = list(cell.robot.home_joints())
    away = list(home)
    away[0] += 1.0
    steps0, t0 = cell.steps(), time.perf_counter()
    for q in (away, home, away, home):
        run(cell.robot.move_joints(q))
    return {"moving_steps_per_s": round((cell.steps() - steps0) / (time.perf_counter() - t0))}


def measure_pick_place(cell: SimCell) -> dict[str, Any]:
    """Real-time factor of a scripted pick-and-place of a box."""
    robot, gripper = cell.robot, cell.gripper
    top = cell.table_top_z
    add_box(cell, (0.04, 0.04, 0.05), (0.5, 0.1))
    cell.wait_sim(0.2)
    sim0, wall0 = cell.time(), time.perf_counter()
    run(robot.move_pose_joint_space(down_at(0.5, 0.1, top + 0.15)))
    run(robot.move_linear(down_at(0.5, 0.1, top + 0.03)))
    run(gripper.close())
    run(robot.move_linear(down_at(0.5, 0.1, top + 0.15)))
    run(robot.move_pose_joint_space(down_at(0.4, -0.2, top + 0.15)))
    run(robot.move_linear(down_at(0.4, -0.2, top + 0.032)))
    run(gripper.open())
    run(robot.move_linear(down_at(0.4, -0.2, top + 0.15)))
    sim_s, wall_s = cell.time() - sim0, time.perf_counter() - wall0
    return {
        "pick_place_sim_s": round(sim_s, 2),
        "pick_place_wall_s": round(wall_s, 3),
        "pick_place_rtf": round(sim_s / wall_s, 1),
    }


def measure_cameras(cell: SimCell) -> dict[str, Any]:
    """Camera frames per second at both sizes (rendered in a client of their own)."""
    from capabilities.sim.cameras import camera_fps

    return {
        "camera_fps_320x240": round(camera_fps((320, 240), frames=20), 1),
        "camera_fps_640x480": round(camera_fps((640, 480), frames=10), 1),
    }


def _python_work_ms() -> float:
    """Wall ms of a workload shaped like perception: thousands of small numpy calls."""
    import numpy as np

    points = np.random.default_rng(0).random((2000, 3))
    started = time.perf_counter()
    for _ in range(3000):
        points = points @ np.eye(3) + 1e-9
        float(np.linalg.norm(points[:10]))
    return (time.perf_counter() - started) * 1000


def measure_python_beside_the_world(cell: SimCell) -> dict[str, Any]:
    """A perception-like workload with the world still, and beside it shared or not."""
    with cell.standing_still():
        alone = _python_work_ms()
    with cell.sharing():
        shared = _python_work_ms()
    unshared = _python_work_ms()
    return {
        "python_work_ms_alone": round(alone, 1),
        "python_work_ms_shared": round(shared, 1),
        "python_work_ms_unshared": round(unshared, 1),
        "python_work_shared_ratio": round(shared / alone, 2),
        "python_work_unshared_ratio": round(unshared / alone, 2),
    }


def measure_cup_to_bin(seed: int = 0) -> dict[str, Any]:
    """Real-time factor of the cup-to-bin plan run by the engine on a fresh simulated cell."""
    from capabilities.base import CapabilityRegistry
    from capabilities.sim.session import SimCellSession
    from engine.build import build_tree
    from engine.executor import run_to_end
    from engine.files import load_plan
    from resources import example_path

    plan_path = example_path("cup_to_bin")
    with SimCellSession("cup_to_bin", seed=seed) as session:
        registry = CapabilityRegistry(cell=session)
        tree = build_tree(load_plan(plan_path), registry, clock=session.clock)
        sim0, wall0 = session.clock(), time.perf_counter()
        result = run_to_end(tree, rate_hz=50.0, timeout=120.0)
        sim_s, wall_s = session.clock() - sim0, time.perf_counter() - wall0
    return {
        "cup_to_bin_status": result.status.value,
        "cup_to_bin_sim_s": round(sim_s, 2),
        "cup_to_bin_wall_s": round(wall_s, 3),
        "cup_to_bin_rtf": round(sim_s / wall_s, 1),
    }


def measurements() -> list[Measurement]:
    """The measurements run, in order, on one cell. Extend this list to add figures."""
    return [
        measure_idle_steps,
        measure_moving_steps,
        measure_pick_place,
        measure_cameras,
        measure_python_beside_the_world,
    ]


def main(argv: list[str] | None = None) -> int:
    """Run every measurement and print the figures (``--json`` for one JSON object)."""
    parser = figures_parser(__doc__)
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    cell = SimCell(speed=None)
    cell.start()
    results: dict[str, Any] = {"start_s": round(time.perf_counter() - t0, 3)}
    try:
        for measure in measurements():
            results.update(measure(cell))
    finally:
        cell.close()
    results.update(measure_cup_to_bin())
    print_figures(results, args.json, 24, indent=2)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
