"""``costar doctor``: one line per check, ok or the fix; exit 0 only when all are ok."""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import sys

import pytest

from capabilities.doctor import CheckResult, check_opengl, check_qt_platform, checks, run_checks


def test_every_line_is_ok_or_a_fix_and_the_exit_code_says_if_all_are_ok() -> None:
    out = io.StringIO()
    good = lambda: CheckResult("first", True, "fine")  # noqa: E731
    bad = lambda: CheckResult("second", False, "install the thing")  # noqa: E731
    assert run_checks([good, bad], out) == 1
    lines = out.getvalue().splitlines()
    assert lines == ["ok   first: fine", "FIX  second: install the thing", "doctor: 1 to fix"]
    assert run_checks([good], io.StringIO()) == 0


def test_a_check_that_breaks_is_a_line_to_fix_not_a_crash() -> None:
    def broken() -> CheckResult:
        raise RuntimeError("driver exploded")

    out = io.StringIO()
    assert run_checks([broken], out) == 1
    assert out.getvalue().startswith(
        "FIX  broken: the check broke: RuntimeError('driver exploded')"
    )


def test_without_a_display_qt_and_opengl_say_how_to_get_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("QT_QPA_PLATFORM", "xcb")
    for check in (check_qt_platform, check_opengl):
        result = check()  # Qt aborts in the probe's process; the doctor goes on
        assert not result.ok
        assert "no display" in result.detail and "xvfb-run" in result.detail


def test_the_checks_cover_python_files_qt_opengl_and_the_simulated_cell_then_a_cell() -> None:
    def robot_answers() -> CheckResult:
        return CheckResult("robot", True, "answers")

    names = [check.__name__ for check in checks([robot_answers])]
    assert names == [
        "check_python",
        "check_shipped_files",
        "check_qt_platform",
        "check_opengl",
        "check_simulated_cell",
        "robot_answers",
    ]


@pytest.mark.sim
def test_costar_doctor_exits_0_on_this_machine() -> None:
    """On a machine set up by the README, under the X server the suite runs with."""
    env = {
        k: v for k, v in os.environ.items() if k not in ("QT_QPA_PLATFORM", "PYTEST_XDIST_WORKER")
    }
    command = [sys.executable, "-m", "capabilities.cli", "doctor"]
    if not env.get("DISPLAY"):
        xvfb = shutil.which("xvfb-run")
        assert xvfb, "the suite runs under Xvfb (packaging/test.sh); xvfb-run is missing"
        command = [xvfb, "-a", "-s", "-screen 0 1280x1024x24", *command]
    done = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 6 and all(line.startswith("ok   ") for line in lines[:5])
    assert "OpenGL" in done.stdout and lines[-1] == "doctor: all ok"


def test_doctor_cell_adds_the_cell_files_checks_after_the_computers(tmp_path) -> None:
    from capabilities.doctor import cell_checks

    bad = tmp_path / "broken.cell.json"
    bad.write_text('{"format_version": 2, "robot": {"kind": "ur"}}', encoding="utf-8")
    args = type("Args", (), {"cell": str(bad)})()
    (cell_check,) = cell_checks(args)
    out = io.StringIO()
    assert run_checks([cell_check], out) == 1
    (line, verdict) = out.getvalue().splitlines()
    assert line.startswith("FIX  cell file: ") and "broken.cell.json" in line
    assert verdict == "doctor: 1 to fix"
    assert cell_checks(type("Args", (), {"cell": None})()) == []
