"""The canvas with a 1000-node plan: time to open until painted, and frame time under status load.

Figures (all in one offscreen QApplication, view 1280 x 800):

- ``open_1000_s``: ``PlanDocument.open`` of a saved 1000-node plan (file read, parse,
  ``plan_reset``, the canvas building every node and link, fitting the tree in view) until
  the end of the first paint of the canvas (``view.grab()``).
- ``frame_ms_median`` / ``frame_ms_p99``: a 30 Hz QTimer calls ``set_statuses`` with all
  1000 nodes changing status each time (as the runtime bridge would in the worst case), and
  each frame is timed from the call until the viewport's next paint event has finished (the
  event loop runs the scene's update processing and the paint). The whole tree is in view
  (the worst case: every node is repainted, as boxes at that zoom). ``*_zoom100`` figures
  are the same at 100 % zoom (full detail, only the nodes on screen are painted).
- ``camera_fps``, ``tick_rate_ratio``, ``scene3d_fps`` (and the figures behind them): the
  camera panel and the 3D scene while a plan runs on the simulated cell, measured by
  ``bench/cell_views.py`` in a process of its own (on the display's GL when there is one).
- ``idle_cpu_cores``: cores the whole app (its process and its children: the live view's
  renderer processes) uses with the simulated cell open at real time, the camera and 3D
  panels shown, no plan running and nothing moving, over ``--idle-seconds`` (30 s; goal at
  most 0.10), measured in a process of its own after the panels showed their first pictures
  and a few seconds' settling. ``idle_camera_frames`` / ``idle_scene3d_frames``: pictures the
  camera panel showed and frames the 3D scene drew meanwhile (0 when idle is quiet).
- ``timeline_scrub_fps``: frames per second while the Timeline panel's slider is dragged
  across a record of 100,000 transitions of the 1000-node plan (synthetic, several changes a
  tick), in the main window on no cell at 1920 x 1080: each frame moves the slider as a drag
  does (``setSliderPosition`` with the slider down) and ends when the canvas has painted the
  moment (its statuses, the Blackboard panel's values, the running nodes); the drag goes
  across the whole run in ``--frames`` steps and back at random (goal at least 30).
  ``timeline_load_s``: reading the record and indexing it.
- ``ngqt_create_node_1000_s``: the peer, NodeGraphQt's own ``NodeGraph.create_node`` with
  its defaults, 1000 times, in the same process (nodes with one input and one output port).

Run from the repository root::

    .venv/bin/python bench/gui.py [--json] [--frames 90] [--idle-seconds 30] [--timeline-only]
"""

from __future__ import annotations

import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEvent, QEventLoop, QObject, QRectF, QTimer
from PySide6.QtWidgets import QApplication

from bench._report import figures_parser, print_figures
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType

__all__ = [
    "build_plan",
    "measure_open",
    "measure_frames",
    "measure_idle",
    "measure_ngqt_create",
    "measure_timeline_scrub",
    "main",
]

_COMPOSITES = (NodeKind.SEQUENCE, NodeKind.SELECTOR, NodeKind.PARALLEL)
_OPS = ("motion.move_to", "perception.detect_object", "gripper.close", "predicates.is_free")


def build_plan(count: int = 1000, seed: int = 1) -> PlanSpec:
    """A plan of ``count`` nodes: composites (about 30 %) and operation leaves with two
    parameters each (a reference and a fixed value), attached at random composites.
    """
    rnd = random.Random(seed)
    root = NodeSpec(NodeKind.SEQUENCE, name="bench root")
    composites = [root]
    for _ in range(count - 1):
        parent = rnd.choice(composites)
        if rnd.random() < 0.3:
            node = NodeSpec(rnd.choice(_COMPOSITES))
            composites.append(node)
        else:
            node = NodeSpec(
                NodeKind.OPERATION,
                op=rnd.choice(_OPS),
                params={
                    "target": Binding.reference("CUP_POSE"),
                    "object": Binding.fixed("CUP", ParamType.TEXT),
                },
            )
        parent.children.append(node)
    return PlanSpec(tree=root, name="bench")


class _PaintCounter(QObject):
    """Counts paint events of a widget (the end of a frame)."""

    def __init__(self) -> None:
        super().__init__()
        self.count = 0

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Paint:
            self.count += 1
        return False


def measure_open(app: QApplication, path: Path) -> tuple[float, Any, Any]:
    """Seconds from ``document.open`` to the end of the first paint; (seconds, doc, view)."""
    from instructor_app.canvas import CanvasView
    from instructor_app.document.editing import PlanDocument

    document = PlanDocument()
    view = CanvasView(document)
    view.resize(1280, 800)
    view.show()
    app.processEvents()
    start = time.perf_counter()
    document.open(path)
    view.grab()
    return time.perf_counter() - start, document, view


def measure_frames(app: QApplication, view: Any, ids: list[str], frames: int) -> list[float]:
    """Frame times (ms) of a 30 Hz timer that changes the status of every node."""
    counter = _PaintCounter()
    viewport = view.viewer.viewport()
    viewport.installEventFilter(counter)
    cycle = (Status.RUNNING, Status.SUCCESS, Status.FAILURE, Status.IDLE)
    times: list[float] = []
    loop = QEventLoop()

    def frame() -> None:
        status = cycle[len(times) % len(cycle)]
        before = counter.count
        start = time.perf_counter()
        view.set_statuses({node_id: status for node_id in ids})
        while counter.count == before:  # until the viewport has painted the change
            app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 5)
        times.append((time.perf_counter() - start) * 1000.0)
        if len(times) >= frames:
            loop.quit()

    timer = QTimer()
    timer.setInterval(33)
    timer.timeout.connect(frame)
    timer.start()
    loop.exec()
    timer.stop()
    viewport.removeEventFilter(counter)
    return times


def measure_timeline_scrub(
    app: QApplication, plan: PlanSpec, frames: int, transitions: int = 100_000
) -> dict[str, Any]:
    """Frames per second of a drag of the Timeline slider over a record of ``plan`` (see
    the module doc).
    """
    from bench._records import write_synthetic_record
    from bench._window import sim_window, wait

    with tempfile.TemporaryDirectory() as folder, sim_window("none") as window:
        record = write_synthetic_record(Path(folder) / "big.trace.jsonl", plan, transitions)
        app.processEvents()
        start = time.perf_counter()
        window.timeline.open_record(record)
        load_s = time.perf_counter() - start
        window.views.canvas.fit_all()
        panel = window.views.timeline
        slider = panel.slider
        counter = _PaintCounter()
        viewport = window.views.canvas.viewer.viewport()
        viewport.installEventFilter(counter)
        app.processEvents()
        canvas = window.views.canvas
        nodes = canvas.mirror.nodes

        def on_screen(changed: dict[str, Any]) -> bool:
            """Whether a changed node shows (a big tree fits only its top in the view)."""
            shown = canvas.viewer.mapToScene(viewport.rect()).boundingRect()
            return any(
                nodes[n].item.sceneBoundingRect().intersects(shown) for n in changed if n in nodes
            )

        wait(1.0)  # what opening the plan left to do (its validation) is done
        rnd = random.Random(2)
        steps = [round(slider.maximum() * i / frames) for i in range(1, frames + 1)]
        steps += [rnd.randint(0, slider.maximum()) for _ in range(frames)]
        slider.setSliderDown(True)
        start = time.perf_counter()
        for value in steps:
            before, shown = counter.count, panel.frames_shown
            slider.setSliderPosition(value)
            deadline = time.perf_counter() + 5.0  # (a frame never takes that long)
            while panel.frames_shown == shown and time.perf_counter() < deadline:
                app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 5)  # the update
            while counter.count == before and on_screen(panel.last_changed):  # its paint
                if time.perf_counter() > deadline:
                    raise RuntimeError(f"the canvas did not paint the moment at {value} ms")
                app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 5)
        elapsed = time.perf_counter() - start
        slider.setSliderDown(False)
        viewport.removeEventFilter(counter)
        transitions = panel.timeline.transitions if panel.timeline else 0
    return {
        "timeline_scrub_fps": round(len(steps) / elapsed, 1),
        "timeline_load_s": round(load_s, 2),
        "timeline_transitions": transitions,
    }


def measure_ngqt_create(count: int = 1000) -> float:
    """Seconds for NodeGraphQt's plain ``create_node`` (defaults) ``count`` times."""
    from NodeGraphQt import BaseNode, NodeGraph

    class PeerNode(BaseNode):
        __identifier__ = "bench.peer"
        NODE_NAME = "node"

        def __init__(self) -> None:
            super().__init__()
            self.add_input("parent")
            self.add_output("children")

    graph = NodeGraph()
    graph.register_node(PeerNode)
    start = time.perf_counter()
    for index in range(count):
        graph.create_node("bench.peer.PeerNode", pos=(index * 10.0, 0.0))
    return time.perf_counter() - start


def _percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(fraction * (len(ordered) - 1)))]


def run_bench(frames: int, idle_seconds: float = 30.0) -> dict[str, Any]:
    app = QApplication.instance() or QApplication([])
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.costar.json"
        save_plan(build_plan(1000), path)
        open_s, document, view = measure_open(app, path)
    ids = [node.id for _, node in document.plan.walk()]
    fit = measure_frames(app, view, ids, frames)
    root = view.item(ids[0]).sceneBoundingRect()
    view.viewer.show_rect(QRectF(root.center().x() - 640, root.top() - 40, 1280, 800))
    zoom100 = measure_frames(app, view, ids, frames)
    view.clear_statuses()
    scrub = measure_timeline_scrub(app, document.plan, frames)
    return {
        "open_1000_s": round(open_s, 3),
        "frame_ms_median": round(statistics.median(fit), 2),
        "frame_ms_p99": round(_percentile(fit, 0.99), 2),
        "frame_ms_median_zoom100": round(statistics.median(zoom100), 2),
        "frame_ms_p99_zoom100": round(_percentile(zoom100, 0.99), 2),
        "ngqt_create_node_1000_s": round(measure_ngqt_create(1000), 3),
        **scrub,
        **measure_cell_views_in_a_process(),
        **measure_idle_in_a_process(idle_seconds),
    }


def _tree_cpu_seconds(root: Any) -> float:
    """CPU seconds (user + system) of a process and its living children so far."""
    total = 0.0
    for proc in [root, *root.children(recursive=True)]:
        try:
            times = proc.cpu_times()
        except Exception:  # a child that ended meanwhile
            continue
        total += times.user + times.system
    return total


def measure_idle(seconds: float, settle: float = 3.0) -> dict[str, Any]:
    """Cores the whole app uses with the simulated cell open, its camera and 3D panels shown,
    nothing running and nothing moving (see the module doc); run in a process of its own.
    """
    import psutil

    from bench._window import sim_window, wait

    _app = QApplication.instance() or QApplication([])
    me = psutil.Process()
    with sim_window() as window:
        for name in ("cameras", "scene3d"):
            window.docks[name].setVisible(True)
        window.arrange_cell_views()
        cameras, scene3d = window.cell_views.cameras, window.cell_views.scene3d
        started = time.perf_counter()
        while len(cameras.shown) < len(cameras._pictures):
            wait(0.1)
            if time.perf_counter() - started > 60.0:
                raise RuntimeError("the camera panel showed no picture within 60 s")
        wait(settle)  # the arm and the objects come to rest, the views catch up
        frames0, drawn0 = cameras.frames_shown, scene3d.frames_drawn
        cpu0, wall0 = _tree_cpu_seconds(me), time.perf_counter()
        wait(seconds)
        cpu1, wall = _tree_cpu_seconds(me), time.perf_counter() - wall0
        result = {
            "idle_cpu_cores": round((cpu1 - cpu0) / wall, 3),
            "idle_camera_frames": cameras.frames_shown - frames0,
            "idle_scene3d_frames": scene3d.frames_drawn - drawn0 if scene3d.available else None,
            "idle_seconds": round(wall, 1),
            "idle_load_average": [round(v, 2) for v in os.getloadavg()],
        }
    return result


def measure_idle_in_a_process(seconds: float) -> dict[str, Any]:
    """:func:`measure_idle` in a process of its own (the display's GL, a fresh cell)."""
    env = dict(os.environ)
    if env.get("DISPLAY"):
        env["QT_QPA_PLATFORM"] = "xcb"
    done = subprocess.run(
        [sys.executable, str(Path(__file__)), "--json", "--idle-only", "--idle-seconds",
         str(seconds)],
        capture_output=True, text=True, env=env, timeout=seconds + 300,
    )  # fmt: skip
    if done.returncode != 0:
        raise RuntimeError(f"bench/gui.py --idle-only failed:\n{done.stderr[-2000:]}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def measure_cell_views_in_a_process() -> dict[str, Any]:
    """bench/cell_views.py's figures; its own process, so that it gets the display's GL
    (this one is offscreen) and a fresh simulated cell.
    """
    env = dict(os.environ)
    if env.get("DISPLAY"):
        env["QT_QPA_PLATFORM"] = "xcb"
    script = Path(__file__).with_name("cell_views.py")
    done = subprocess.run(
        [sys.executable, str(script), "--json"], capture_output=True, text=True, env=env,
        timeout=300,
    )  # fmt: skip
    if done.returncode != 0:
        raise RuntimeError(f"bench/cell_views.py failed:\n{done.stderr[-2000:]}")
    result: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def main(argv: list[str] | None = None) -> int:
    """Print the figures (``--json``: one JSON object)."""
    parser = figures_parser(__doc__)
    parser.add_argument("--frames", type=int, default=90, help="frames per measurement")
    parser.add_argument(
        "--idle-seconds", type=float, default=30.0, help="length of the idle measurement"
    )
    parser.add_argument(
        "--idle-only", action="store_true", help="only the idle figures (in this process)"
    )
    parser.add_argument("--timeline-only", action="store_true", help="only the timeline figures")
    args = parser.parse_args(argv)
    if args.timeline_only:
        app = QApplication.instance() or QApplication([])
        print_figures(measure_timeline_scrub(app, build_plan(1000), args.frames), args.json, 26)
        return 0
    if args.idle_only:
        print_figures(measure_idle(args.idle_seconds), args.json, 26)
        return 0
    results = run_bench(args.frames, args.idle_seconds)
    print_figures(results, args.json, 26, indent=2)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
