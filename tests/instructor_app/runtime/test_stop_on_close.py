"""The Instructor on a UR cell (the loopback emulator through ur_rtde) halts the arm however it
ends: its window closed during a run, or a signal (kill, Ctrl-C, a closed terminal).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from capabilities.ur_emulator.process import EmulatorProcess
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import JointConfig, ParamType
from instructor_app.runtime.session import CellSession
from tests.capabilities.ur.emulators import HOME, wait_for
from tests.instructor_app.gui_driver import make_window

pytestmark = pytest.mark.sim

ROOT = Path(__file__).resolve().parents[3]
FAR = 2.4  # rad: the base joint's turn, which the arm must not finish
STILL = 1e-4  # rad


def _turn_plan(tmp_path: Path) -> Path:
    target = JointConfig((HOME[0] + FAR, *HOME[1:]))
    move = NodeSpec(NodeKind.OPERATION, "turn", op="motion.move_joints", params={
        "target": Binding.fixed(target, ParamType.JOINTS),
        "speed": Binding.fixed(0.5, ParamType.NUMBER),
    })  # fmt: skip
    path = tmp_path / "turn.costar.json"
    save_plan(PlanSpec(move, "turn"), path)
    return path


def _stands_short_of_the_target(emulator: EmulatorProcess) -> None:
    assert wait_for(lambda: not emulator.state()["moving"], 10), "the arm did not stop"
    q = emulator.state()["q"]
    assert not wait_for(
        lambda: max(abs(a - b) for a, b in zip(emulator.state()["q"], q, strict=True)) > STILL,
        0.5,
    ), "the arm moves on"
    assert q[0] < HOME[0] + FAR - 1.0


def test_closing_the_window_during_a_run_halts_the_arm(qtbot, tmp_path: Path, emulator) -> None:
    session = CellSession(str(tmp_path / "emulated.cell.json"))
    assert session.open()
    try:
        window = make_window(qtbot, session, tmp_path, rate_hz=20.0)
        assert window.open_plan(_turn_plan(tmp_path))
        assert window.controller.run()
        qtbot.waitUntil(lambda: emulator.state()["q"][0] > HOME[0] + 0.3, timeout=30_000)
        assert window.close()  # the close button: the plan is saved, nothing is asked
        _stands_short_of_the_target(emulator)
    finally:
        session.close()  # as the application does once its window closed
    assert emulator.state()["program_running"] is False  # the control script ended too


def test_a_signal_to_the_instructor_halts_the_arm_and_ends_it(tmp_path: Path, emulator) -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), COSTAR_LIBRARY=str(tmp_path / "library"))
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    env["XDG_CONFIG_HOME"] = str(tmp_path / "config")  # never the user's settings
    env["XDG_DATA_HOME"] = str(tmp_path / "data")
    app = subprocess.Popen(
        [sys.executable, "-m", "instructor_app.app", str(_turn_plan(tmp_path)), "--cell",
         str(tmp_path / "emulated.cell.json"), "--run"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=str(ROOT),
    )  # fmt: skip
    try:
        assert wait_for(lambda: emulator.state()["q"][0] > HOME[0] + 0.3, 90)
        app.send_signal(signal.SIGTERM)
        _stands_short_of_the_target(emulator)
        out, _ = app.communicate(timeout=60)
    finally:
        if app.poll() is None:
            app.kill()
            app.communicate(timeout=30)
    assert app.returncode == 0, out
    assert emulator.state()["program_running"] is False
