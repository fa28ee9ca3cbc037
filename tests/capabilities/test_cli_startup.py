"""Commands that need no cell import no simulator, vision or robot library (issue 23).

Their start-up time is measured by ``bench/cli.py``; here only what they import is checked, in
a fresh interpreter, so no time is asserted.
"""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

from capabilities.cli import main

REPO_ROOT = Path(__file__).resolve().parents[2]

# What made `costar validate --cell none` take 1.3 s and 320 MB: Open3D (with dash and
# plotly), OpenCV and numpy through the capabilities' operation modules; the simulator
# (pybullet), Qt and ur_rtde are there for cells and the GUI only.
HEAVY = (
    "numpy",
    "cv2",
    "open3d",
    "scipy",
    "pybullet",
    "PySide6",
    "rtde_control",
    "rtde_receive",
    "rtde_io",
    "dashboard_client",
    "capabilities.sim",
    "capabilities.ur",
)

_PROBE = """
import io, json, sys
from capabilities.cli import main
codes = [main(argv, io.StringIO(), io.StringIO()) for argv in json.loads(sys.argv[1])]
print(json.dumps({"codes": codes, "loaded": sorted(m for m in json.loads(sys.argv[2])
                                                   if m in sys.modules)}))
"""


def _commands(tmp_path: Path) -> list[list[str]]:
    xml = tmp_path / "selector.xml"
    trace = tmp_path / "selector.trace.jsonl"
    argv = ["run", "example:nodes/selector", "--cell", "none", "--trace", str(trace)]
    code = main(argv, io.StringIO(), io.StringIO())
    assert code == 0 and trace.exists()
    return [
        ["validate", "example:nodes/selector", "--cell", "none"],
        ["export-xml", "example:nodes/selector", str(xml)],
        ["import-xml", str(xml), str(tmp_path / "imported.costar.json")],
        ["examples"],
        ["ops", "--cell", "none"],
        ["ops", "--cell", "none", "--json"],
        ["trace", "show", str(trace)],
    ]


def test_commands_without_a_cell_import_no_heavy_library(tmp_path: Path) -> None:
    commands = _commands(tmp_path)
    # This repository's code, also when another checkout is the one installed.
    path = [str(REPO_ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(path))
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, json.dumps(commands), json.dumps(HEAVY)],
        capture_output=True, text=True, timeout=120, cwd=REPO_ROOT, env=env,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["codes"] == [0] * len(commands)
    assert result["loaded"] == []


def test_every_capability_lists_its_operations_without_a_cell() -> None:
    """The manifests stay available with the heavy libraries left out: every capability
    registered, each with its operations (the vision and geometry ones included).
    """
    from capabilities.base import CapabilityRegistry

    registry = CapabilityRegistry()
    by_capability: dict[str, int] = {}
    for made in registry.manifests():
        by_capability[made.capability] = by_capability.get(made.capability, 0) + 1
    for name in ("collaboration", "markers", "occupancy", "perception", "predicates"):
        assert by_capability.get(name, 0) > 0, name
