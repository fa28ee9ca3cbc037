"""Opening a cell from the Instructor: how long the GUI thread stalls, in the background and
(the peer, what the window did before) on the GUI thread, in the same run.

Figures:

- ``sim_open_s``: time from the call until the simulated cell is in use (``cell_ready``).
- ``gui_stall_ms_background``: the longest gap between ticks of a 5 ms QTimer while the
  simulated cell opens with ``CellSession.open_in_background`` (the window's way).
- ``gui_stall_ms_sync``: the same with ``CellSession.open`` (the caller waits: what the
  window did before; the peer).
- ``dead_host_fail_s`` / ``gui_stall_ms_dead_host``: a UR cell file whose host (loopback,
  nothing listening) refuses: time until ``cell_ready(False)`` and the longest stall.
- ``ur_open_s`` / ``gui_stall_ms_ur``: a UR cell file pointing at the loopback emulator
  (``costar ur-emulator`` in a process of its own, spoken to by ur_rtde), in the background.
- ``stall_ratio``: background / sync stall while the simulated cell opens.

The simulated cell runs pybullet in this process, and pybullet holds the GIL while it loads
the scene: that part of its start stalls the GUI thread wherever it runs.

Run from the repository root::

    .venv/bin/python bench/cell_open.py [--json] [--reps 3] [--host 127.254.0.2]
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEventLoop, QTimer
from PySide6.QtWidgets import QApplication

from bench._report import figures_parser, print_figures
from capabilities.ur_emulator.process import EmulatorProcess
from instructor_app.runtime.session import CellSession

__all__ = ["measure", "main"]


class _StallMeter:
    """The longest gap between the ticks of a 5 ms timer on the GUI thread."""

    def __init__(self) -> None:
        self.longest = 0.0
        self._last = time.perf_counter()
        self._timer = QTimer()
        self._timer.setInterval(5)
        self._timer.timeout.connect(self._tick)

    def _tick(self) -> None:
        now = time.perf_counter()
        self.longest = max(self.longest, now - self._last)
        self._last = now

    def __enter__(self) -> _StallMeter:
        self._last = time.perf_counter()
        self._timer.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._tick()
        self._timer.stop()


def _open(session: CellSession, name: str, background: bool) -> tuple[float, float, bool]:
    """(seconds until the opening ended, longest GUI stall in s, whether it opened)."""
    ok: list[bool] = []
    loop = QEventLoop()

    def ready(result: bool) -> None:
        ok.append(result)
        loop.quit()

    session.cell_ready.connect(ready)
    with _StallMeter() as meter:
        start = time.perf_counter()
        if background:
            session.open_in_background(name)
            if not ok:
                loop.exec()
        else:
            session.open(name)
            loop.processEvents()  # the ticks the wait held back
        elapsed = time.perf_counter() - start
    session.cell_ready.disconnect(ready)
    return elapsed, meter.longest, ok[-1]


def measure(reps: int = 3, host: str = "127.254.0.2") -> dict[str, Any]:
    """The figures of the module docstring (medians over ``reps`` openings each)."""
    figures: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="costar-bench-") as scratch:
        dead = Path(scratch, "dead.cell.json")
        robot = {"kind": "ur", "host": "127.254.0.1", "model": "UR5e"}
        dead.write_text(json.dumps({"format_version": 2, "robot": robot}), "utf-8")
        emulated = Path(scratch, "emulated.cell.json")
        with EmulatorProcess(host, "5.12", unlock_delay=0.0, write_cell=emulated):
            _collect(figures, reps, [
                ("background", "sim", True),
                ("sync", "sim", False),
                ("dead_host", str(dead), True),
                ("ur", str(emulated), True),
            ])  # fmt: skip
    med = {key: statistics.median(values) for key, values in figures.items()}
    return {
        "sim_open_s": round(med["open_s_background"], 3),
        "gui_stall_ms_background": round(med["gui_stall_ms_background"], 1),
        "gui_stall_ms_sync": round(med["gui_stall_ms_sync"], 1),
        "dead_host_fail_s": round(med["open_s_dead_host"], 3),
        "gui_stall_ms_dead_host": round(med["gui_stall_ms_dead_host"], 1),
        "ur_open_s": round(med["open_s_ur"], 3),
        "gui_stall_ms_ur": round(med["gui_stall_ms_ur"], 1),
        "stall_ratio": round(med["gui_stall_ms_background"] / med["gui_stall_ms_sync"], 3),
    }


def _collect(figures: dict[str, list[float]], reps: int, kinds: list[Any]) -> None:
    for _ in range(reps):
        for key, name, background in kinds:
            session = CellSession("none", speed=1.0)
            session.open("none")
            elapsed, stall, ok = _open(session, name, background)
            session.close()
            if ok != (key != "dead_host"):
                raise SystemExit(f"error: opening {name} did not end as expected")
            figures.setdefault(f"open_s_{key}", []).append(elapsed)
            figures.setdefault(f"gui_stall_ms_{key}", []).append(stall * 1000)


def main(argv: list[str] | None = None) -> int:
    """Measure the GUI thread while cells open; print the figures (``--json``: one JSON object)."""
    parser = figures_parser(__doc__)
    parser.add_argument("--reps", type=int, default=3, help="openings of each kind")
    parser.add_argument("--host", default="127.254.0.2", help="loopback address of the emulator")
    args = parser.parse_args(argv)
    _app = QApplication.instance() or QApplication([])
    result = measure(max(1, args.reps), args.host)
    print_figures(result, args.json, 26)
    return 0


if __name__ == "__main__":
    sys.exit(main())
