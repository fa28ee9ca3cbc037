"""bench/gui.py's idle figures keep their shape: a short idle window of the app on the
simulated cell gives ``idle_cpu_cores`` and the frames drawn meanwhile (figures not asserted).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_a_short_idle_window_prints_the_idle_figures() -> None:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONPATH=str(REPO_ROOT))
    env.pop("DISPLAY", None)
    done = subprocess.run(
        [sys.executable, str(REPO_ROOT / "bench" / "gui.py"), "--json", "--idle-only",
         "--idle-seconds", "2"],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    assert {"idle_cpu_cores", "idle_camera_frames", "idle_scene3d_frames"} <= set(figures)
    assert figures["idle_cpu_cores"] >= 0 and figures["idle_seconds"] >= 2
