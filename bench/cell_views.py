"""The camera panel and the 3D scene while a plan runs on the simulated cell (real time).

One main window on the simulated cell runs ``cup_to_bin_vision`` forever; the run alternates
between phases with the camera and 3D docks hidden (nothing captured or drawn) and shown:

- ``camera_fps``: pictures per second each camera shows in the camera panel (320x240) while
  the plan runs (goal at least 15).
- ``tick_rate_ratio``: engine ticks per second with the panels shown / with them hidden, in
  the same run (goal at least 0.9).
- ``scene3d_fps``: frames per second the 3D scene draws while the arm moves (null where no
  OpenGL context can be made: run under xvfb-run).
- ``sim_speed_on`` / ``sim_speed_off``: simulated seconds per wall second in each phase.
- ``camera_fps_by_camera``: frames each camera's feed captured per second (shown phase).
- ``renderer_cpu_ms_per_frame``: CPU time each camera's live-view renderer process spent per
  frame (independent of the load; 1000 / it is what an idle core would give).
- ``app_cpu_on`` / ``app_cpu_off``: cores the app's own process used in each phase.
- ``first_picture_s``: seconds from starting the plan to the first picture of every camera
  (the live view's renderer processes start); both phases are measured after it.
- ``load_average``: the machine's load (1, 5, 15 min) at the end: the figures depend on it.
- ``panel_sizes``: width and height (px) of the camera panel and of the 3D scene's GL view
  as laid out (a 1920 x 1080 window: the cameras above the 3D scene in a column of their own,
  as the Instructor places them in a window that wide).

Run it on its own or through ``bench/gui.py`` (which runs it in a process of its own with
``QT_QPA_PLATFORM=xcb`` when there is a display)::

    xvfb-run -a .venv/bin/python bench/cell_views.py --json
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

if not os.environ.get("DISPLAY"):
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtWidgets import QApplication

from bench._report import figures_parser, print_figures
from bench._window import sim_window, wait
from engine.tree import RunPolicy

__all__ = ["measure_cell_views", "main"]

PLAN = (
    Path(__file__).resolve().parents[1] / "resources" / "examples" / "cup_to_bin_vision.costar.json"
)


def _cpu_seconds(pid: int) -> float | None:
    """CPU time (user + system) a process has used so far (Linux; None elsewhere)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _renderers(cell: Any) -> dict[str, int]:
    """Camera -> process id of its live-view renderer (none on a cell without one)."""
    live = getattr(cell, "live_view", None)
    return live.pids() if live is not None else {}


def _first_pictures(window: Any, timeout: float = 60.0) -> float:
    """Seconds until the camera panel shows a picture of every camera: the live view's
    renderers start once (a fresh process each), before either phase is measured.
    """
    cameras, started = window.cell_views.cameras, time.perf_counter()
    while len(cameras.shown) < len(cameras._pictures):
        wait(0.1)
        if time.perf_counter() - started > timeout:
            raise RuntimeError(f"the camera panel showed no picture within {timeout:g} s")
    return time.perf_counter() - started


def _on_screen(window: Any) -> dict[str, list[int]]:
    """Sizes of the camera panel and the 3D view; raises unless both lie inside the window
    (tabbed away or squeezed off it, they would be drawn where nobody sees them).
    """
    inside = window.rect()
    sizes: dict[str, list[int]] = {}
    for name, widget in (
        ("cameras", window.cell_views.cameras),
        ("scene3d", window.cell_views.scene3d),
    ):
        corner = widget.mapTo(window, widget.rect().topLeft())
        if not (widget.isVisible() and inside.contains(widget.rect().translated(corner))):
            raise RuntimeError(f"the {name} panel is not on screen: the figures would not count")
        sizes[name] = [widget.width(), widget.height()]
    view = window.cell_views.scene3d.view
    if view is not None:
        sizes["scene3d_gl"] = [view.width(), view.height()]
    return sizes


def _phase(window: Any, shown: bool, seconds: float) -> dict[str, Any]:
    views = window.cell_views
    for name in ("cameras", "scene3d"):
        window.docks[name].setVisible(shown)
    if shown:  # shown again, the docks come back narrower: the column of a window this wide
        window.arrange_cell_views()
    wait(1.0)  # settle: the feed starts or stops, the docks lay out
    sizes = _on_screen(window) if shown else {}
    executor = window.controller._executor  # the bench reads the engine's tick counter
    cell = window.session.cell
    ticks0, sim0, wall0 = executor.tree.ctx.tick_count, cell.sim.time(), time.perf_counter()
    frames0, drawn0 = views.cameras.frames_shown, views.scene3d.frames_drawn
    seq0 = {name: frame.seq for name, frame in views.cameras.shown.items()}
    cpu0 = {name: _cpu_seconds(pid) for name, pid in _renderers(cell).items()}
    app0 = _cpu_seconds(os.getpid())
    wait(seconds)
    wall = time.perf_counter() - wall0
    app1 = _cpu_seconds(os.getpid())
    cameras = max(len(views.cameras.shown), 1)
    return {
        "ticks_per_s": (executor.tree.ctx.tick_count - ticks0) / wall,
        "camera_fps": (views.cameras.frames_shown - frames0) / wall / cameras,
        "scene3d_fps": (views.scene3d.frames_drawn - drawn0) / wall,
        "sim_speed": (cell.sim.time() - sim0) / wall,
        # Frames each camera's feed captured (the panel may show fewer).
        "per_camera": {
            name: round((frame.seq - seq0.get(name, 0)) / wall, 1)
            for name, frame in views.cameras.shown.items()
        },
        "app_cpu": None if app0 is None or app1 is None else (app1 - app0) / wall,
        "sizes": sizes,
        # CPU milliseconds each renderer process spent per frame: what a frame costs whatever
        # the machine's load (1000 / it is the rate one idle core would give).
        "cpu_ms_per_frame": {
            name: round(1000 * (cpu - start) / max(frame.seq - seq0.get(name, 0), 1), 1)
            for name, frame in views.cameras.shown.items()
            if (start := cpu0.get(name)) is not None
            and (cpu := _cpu_seconds(_renderers(cell).get(name, -1))) is not None
        },
    }


def _joined(phases: list[dict[str, Any]]) -> dict[str, Any]:
    """Phases of the same kind as one: the rates averaged, the rest of the last one."""
    joined = dict(phases[-1])
    for rate in ("ticks_per_s", "camera_fps", "scene3d_fps", "sim_speed"):
        joined[rate] = sum(phase[rate] for phase in phases) / len(phases)
    cpus = [phase["app_cpu"] for phase in phases]
    joined["app_cpu"] = None if None in cpus else sum(cpus) / len(cpus)
    return joined


def measure_cell_views(seconds: float = 6.0) -> dict[str, Any]:
    """The camera panel's and the 3D scene's frame rates and the app's CPU while a plan runs,
    with the views on and off.
    """
    app = QApplication.instance() or QApplication([])
    with sim_window() as window:
        window.document.open(PLAN)
        window.document.set_run_policy(RunPolicy.FOREVER)
        assert window.controller.run(), "the plan did not start"
        first_picture = _first_pictures(window)
        # Off and on in turns, each half the time twice: in lockstep the world and the engine
        # stand still while the plan looks, so one long phase of each would compare parts of
        # the plan (a look in one, a move in the other), not the panels' cost.
        halves = [_phase(window, shown, seconds / 2) for shown in (False, True, False, True)]
        off, on = _joined(halves[0::2]), _joined(halves[1::2])
        app.processEvents()
    gl = window.cell_views.scene3d.available
    return {
        "camera_fps": round(on["camera_fps"], 1),
        "tick_rate_ratio": round(on["ticks_per_s"] / off["ticks_per_s"], 3),
        "scene3d_fps": round(on["scene3d_fps"], 1) if gl else None,
        "ticks_per_s_panels_on": round(on["ticks_per_s"], 1),
        "ticks_per_s_panels_off": round(off["ticks_per_s"], 1),
        "sim_speed_on": round(on["sim_speed"], 2),
        "sim_speed_off": round(off["sim_speed"], 2),
        "camera_fps_by_camera": on["per_camera"],
        "first_picture_s": round(first_picture, 1),
        "renderer_cpu_ms_per_frame": on["cpu_ms_per_frame"],
        # Cores the app's own process used (physics, engine, GUI, feed): with / without panels.
        "app_cpu_on": on["app_cpu"] and round(on["app_cpu"], 2),
        "app_cpu_off": off["app_cpu"] and round(off["app_cpu"], 2),
        # Others' work on the machine: compare figures only with runs under a similar load.
        "load_average": [round(v, 2) for v in os.getloadavg()],
        "panel_sizes": on["sizes"],
    }


def main(argv: list[str] | None = None) -> int:
    """Print the figures (``--json``: one JSON object)."""
    parser = figures_parser(__doc__)
    parser.add_argument("--seconds", type=float, default=6.0, help="length of each phase")
    args = parser.parse_args(argv)
    results = measure_cell_views(args.seconds)
    print_figures(results, args.json, 26)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
