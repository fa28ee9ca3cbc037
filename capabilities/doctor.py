"""``costar doctor``: can this computer run the Instructor? One line per check, ok or the fix.

Each check is a small function that returns a :class:`CheckResult`; :func:`checks` lists
them in the order they are printed. A check of a real cell (the robot answers, the cameras
stream) is one more such function, returned by :func:`cell_checks` for the cell file the
command line names.

Qt and OpenGL are probed in a child Python process: a missing platform plugin makes Qt abort
the process, and a broken OpenGL driver can crash it, and neither may take the doctor down.
The probes are also why this module, in the Qt-free ``capabilities`` layer, may name Qt: it
never imports it, it asks a separate interpreter whether Qt starts.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from collections.abc import Callable, Sequence
from typing import TextIO

from capabilities.check_result import CheckResult
from resources import example_plans, resource_path

__all__ = ["CheckResult", "cell_checks", "checks", "cmd_doctor", "run_checks"]

MIN_PYTHON = (3, 11)
PROBE_TIMEOUT = 60.0  # s; a first start of Qt or Mesa on a slow PC can take a while
INSTALL_HINT = "run bash packaging/install.sh (it installs the system libraries Qt needs)"


# A check returns one result, or several when one probe answers several questions (a robot
# connection: reachable, version, modes).
Check = Callable[[], "CheckResult | list[CheckResult]"]


def check_python() -> CheckResult:
    """The interpreter is recent enough."""
    version = ".".join(map(str, sys.version_info[:3]))
    if sys.version_info[:2] >= MIN_PYTHON:
        return CheckResult("Python", True, f"{version} ({sys.executable})")
    needed = ".".join(map(str, MIN_PYTHON))
    return CheckResult("Python", False, f"{version} is too old: install Python {needed} or newer")


def check_shipped_files() -> CheckResult:
    """The package data (examples, scenes, objects, robot models) is where it should be."""
    needed = [resource_path(*parts) for parts in _NEEDED_FILES]
    missing = [str(path) for path in needed if not path.exists()]
    if missing or not example_plans():
        what = ", ".join(missing) or "the example plans"
        return CheckResult("shipped files", False, f"missing {what}: reinstall the application")
    return CheckResult("shipped files", True, str(resource_path()))


_NEEDED_FILES = (
    ("cells", "sim_default.json"),
    ("scenes", "cup_to_bin.json"),
    ("objects", "cup", "model.json"),
    ("robots", "parallel_gripper.urdf.xml"),
    ("schemas", "plan.schema.json"),
)

_QT_PROBE = """
import sys
from PySide6.QtGui import QGuiApplication
app = QGuiApplication(sys.argv[:1])
print(app.platformName())
"""

_GL_PROBE = """
import sys
from PySide6.QtGui import QGuiApplication, QOffscreenSurface, QOpenGLContext
app = QGuiApplication(sys.argv[:1])
context = QOpenGLContext()
if not context.create():
    sys.exit("no OpenGL context could be created")
surface = QOffscreenSurface()
surface.setFormat(context.format())
surface.create()
if not context.makeCurrent(surface):
    sys.exit("the OpenGL context cannot be made current")
gl = context.functions()
print(f"OpenGL {gl.glGetString(0x1F02)} on {gl.glGetString(0x1F01)}")  # VERSION, RENDERER
"""


def _probe(code: str) -> tuple[bool, str]:
    """Run ``code`` in a child interpreter: (it exited 0, its output or what went wrong)."""
    try:
        done = subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            timeout=PROBE_TIMEOUT,
        )
    except subprocess.TimeoutExpired:
        return False, f"no answer within {PROBE_TIMEOUT:.0f} s"
    if done.returncode == 0:
        return True, done.stdout.strip()
    lines = [line.strip() for line in (done.stderr + done.stdout).splitlines() if line.strip()]
    return False, _first_telling_line(lines) or f"the probe exited with {done.returncode}"


def _first_telling_line(lines: list[str]) -> str:
    """The line of a failed probe that says most: Qt's plugin message, else the last one."""
    for line in lines:
        if "platform plugin" in line or "display" in line.lower():
            return line
    return lines[-1] if lines else ""


def _display_fix(problem: str) -> str:
    """How to fix a Qt start failure: a display to use, or the system libraries."""
    has_display = bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    if "No module named" in problem:
        return f"{problem}: reinstall the application (bash packaging/install.sh)"
    if not has_display:
        return f"{problem}: no display; start it from the desktop or under xvfb-run"
    return f"{problem}: {INSTALL_HINT}"


def check_qt_platform() -> CheckResult:
    """Qt starts on this display (its platform plugin loads)."""
    ok, said = _probe(_QT_PROBE)
    if ok:
        return CheckResult("Qt platform", True, f"plugin {said}")
    return CheckResult("Qt platform", False, _display_fix(said))


def check_opengl() -> CheckResult:
    """An OpenGL context can be made (the 3D view of the cell needs one)."""
    ok, said = _probe(_GL_PROBE)
    if ok:
        return CheckResult("OpenGL", True, said)
    return CheckResult("OpenGL", False, _display_fix(said) + " (or install Mesa: libgl1-mesa-dri)")


def check_simulated_cell() -> CheckResult:
    """The simulated cell starts (pybullet, the robot model, the default scene) and closes."""
    from capabilities.cells import CellError, open_cell  # pybullet loads only for this check

    try:
        with open_cell("sim", seed=0, start=True) as cell:
            arm = "an arm" if "arm" in cell.interfaces() else "no arm"
    except CellError as exc:
        return CheckResult("simulated cell", False, f"{exc}: reinstall the application")
    return CheckResult("simulated cell", True, f"started with {arm} and closed")


def checks(extra: Sequence[Check] = ()) -> list[Check]:
    """The checks to run, in order: this computer's, then ``extra`` (a real cell's)."""
    return [
        check_python,
        check_shipped_files,
        check_qt_platform,
        check_opengl,
        check_simulated_cell,
        *extra,
    ]


def cell_checks(args: argparse.Namespace) -> list[Check]:
    """The checks of the cell file ``--cell`` names: the file, the robot answering, each camera
    giving a frame (:mod:`capabilities.ur.doctor`, imported only when a cell is named).
    """
    path = getattr(args, "cell", None)
    if not path:
        return []

    def check_cell() -> list[CheckResult]:
        from capabilities.ur.doctor import cell_checks as ur_cell_checks

        return ur_cell_checks(path)

    return [check_cell]


def run_checks(to_run: list[Check], out: TextIO) -> int:
    """Run each check, print its line; 0 when all are ok, else 1."""
    failed = 0
    for check in to_run:
        try:
            found = check()
        except Exception as exc:  # a check that breaks is a failed check, not a crash
            found = CheckResult(check.__name__, False, f"the check broke: {exc!r}")
        for result in found if isinstance(found, list) else [found]:
            mark = "ok  " if result.ok else "FIX "
            print(f"{mark} {result.name}: {result.detail}", file=out, flush=True)
            failed += not result.ok
    verdict = "all ok" if not failed else f"{failed} to fix"
    print(f"doctor: {verdict}", file=out)
    return 0 if not failed else 1


def cmd_doctor(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """``costar doctor``: exit 0 when every check is ok, 1 when one needs a fix."""
    return run_checks(checks(cell_checks(args)), out)
