"""Stop means stop: whatever ends the program that drives the arm, the arm halts.

A UR goes on with its last move when the program that sent it dies. Closing the connection
halts the arm first; a signal to ``costar run`` closes it; a killed program is stopped by the
control script's RTDE watchdog. Each test checks where the arm stood still: far from the
target of the long move it was on, which it would have reached had nothing stopped it.
"""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
from pathlib import Path

import dashboard_client
import pytest
import rtde_control

from capabilities.cli import main
from capabilities.ur.errors import URError, ur_words
from capabilities.ur_emulator.process import EmulatorProcess
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import JointConfig, ParamType
from tests.capabilities.ur.emulators import HOME, wait_for

ROOT = Path(__file__).resolve().parents[3]
FAR = 2.4  # rad the base joint turns in the long move
STILL = 1e-4  # rad: a joint that moves less over half a second stands still


def _plan_file(tmp_path: Path, offsets: tuple[float, ...], speed: float) -> Path:
    moves = [
        NodeSpec(
            NodeKind.OPERATION,
            f"move {i}",
            op="motion.move_joints",
            params={
                "target": Binding.fixed(JointConfig((HOME[0] + o, *HOME[1:])), ParamType.JOINTS),
                "speed": Binding.fixed(speed, ParamType.NUMBER),
            },
        )
        for i, o in enumerate(offsets)
    ]
    path = tmp_path / "moves.costar.json"
    save_plan(PlanSpec(NodeSpec(NodeKind.SEQUENCE, "moves", children=moves), "moves"), path)
    return path


def _standing_still(emulator: EmulatorProcess) -> list[float]:
    """Wait until the arm stops; its joints, which then stay where they are."""
    assert wait_for(lambda: not emulator.state()["moving"], 10), "the arm did not stop"
    first = emulator.state()["q"]
    assert not wait_for(lambda: _moved(emulator, first), 0.5), "the arm moves on"
    return list(first)


def _moved(emulator: EmulatorProcess, q: list[float]) -> bool:
    return max(abs(a - b) for a, b in zip(emulator.state()["q"], q, strict=True)) > STILL


def _costar_run(plan: Path, cell: Path, *options: str) -> subprocess.Popen[str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen(
        [sys.executable, "-m", "capabilities.cli", "run", str(plan), "--cell", str(cell),
         *options],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=str(ROOT),
    )  # fmt: skip


def _finish(run: subprocess.Popen[str]) -> str:
    """Its output once it ended by itself (killed only when it does not within 60 s)."""
    try:
        out, _ = run.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        run.kill()
        out, _ = run.communicate(timeout=30)
    return out


@pytest.mark.sim
def test_closing_the_connection_halts_the_move_and_ends_the_control_script(
    start_emulator, connect
) -> None:
    emulator = start_emulator()
    connection, arm = connect(emulator)
    arm.move_joints((HOME[0] + FAR, *HOME[1:]), speed=0.5)
    assert wait_for(lambda: emulator.state()["q"][0] > HOME[0] + 0.2, 20)
    connection.close()  # at once: the move's handle is not even cancelled
    q = _standing_still(emulator)
    assert q[0] < HOME[0] + FAR - 1.0
    assert emulator.state()["program_running"] is False


@pytest.mark.sim
@pytest.mark.parametrize("name", ["SIGTERM", "SIGKILL"])
def test_a_signalled_costar_run_leaves_the_arm_standing(
    tmp_path: Path, start_emulator, name: str
) -> None:
    """SIGTERM (as Ctrl-C and a closed terminal) ends the run, which halts the arm before it
    closes the connection; SIGKILL gives the program no say: the script's watchdog stops it.
    """
    cell = tmp_path / "emulated.cell.json"
    emulator = start_emulator(write_cell=cell)
    run = _costar_run(_plan_file(tmp_path, (0.0, FAR), 0.6), cell)
    try:
        assert wait_for(lambda: emulator.state()["q"][0] > HOME[0] + 0.3, 60)
        run.send_signal(getattr(signal, name))
        q = _standing_still(emulator)
    finally:
        out = _finish(run)
    assert q[0] < HOME[0] + FAR - 0.5, out
    assert emulator.state()["program_running"] is False
    if name == "SIGTERM":
        assert run.returncode == 3 and "stopped after" in out, out
    else:
        assert any("watchdog" in m for m in emulator.state()["messages"])


@pytest.mark.sim
def test_the_emulated_watchdog_stops_a_program_nobody_kicks(start_emulator) -> None:
    emulator = start_emulator()
    control = rtde_control.RTDEControlInterface(emulator.host)
    try:
        assert control.setWatchdog(5.0)
        for _ in range(30):  # kicked: it runs on
            assert control.kickWatchdog()
            wait_for(lambda: False, 0.02)
        assert emulator.state()["program_running"] is True
        target = [HOME[0] + FAR, *HOME[1:]]
        assert control.moveJ(target, 0.5, 1.4, True)
        # Nobody kicks any more: the program stops within the watchdog's period, and the arm.
        q = _standing_still(emulator)
        assert q[0] < HOME[0] + FAR - 1.0
        assert emulator.state()["program_running"] is False
        assert any("RTDE watchdog" in m for m in emulator.state()["messages"])
    finally:
        control.disconnect()


@pytest.mark.sim
def test_costar_run_gives_up_on_a_dead_control_script_after_the_hold_timeout(
    tmp_path: Path, start_emulator
) -> None:
    cell = tmp_path / "emulated.cell.json"
    emulator = start_emulator(write_cell=cell)
    out, err = io.StringIO(), io.StringIO()
    plan = _plan_file(tmp_path, (0.9,), 0.3)

    def kill_it() -> None:
        assert wait_for(lambda: emulator.state()["moving"], 30)
        emulator.kill_script()

    import threading

    threading.Thread(target=kill_it, daemon=True).start()
    args = ["run", str(plan), "--cell", str(cell), "--hold-timeout", "1.5", "--timeout", "60"]
    code = main(args, out, err)
    text = out.getvalue()
    assert code == 3, text + err.getvalue()
    assert "held: the control script is not running" in text
    assert "gave up after 2 s held: the control script is not running" in text
    assert "the robot: robot mode RUNNING, safety mode NORMAL, program STOPPED" in text


@pytest.mark.sim
def test_costar_run_says_a_controller_is_gone_with_its_last_state(
    tmp_path: Path, start_emulator
) -> None:
    cell = tmp_path / "emulated.cell.json"
    emulator = start_emulator(write_cell=cell)
    run = _costar_run(_plan_file(tmp_path, (0.9,), 0.3), cell, "--hold-timeout", "3")
    try:
        assert wait_for(lambda: emulator.state()["moving"], 60)
        emulator.kill()  # the controller dies
    finally:
        out = _finish(run)
    assert run.returncode == 3, out
    assert "held: connection lost" in out
    gave_up = next(line for line in out.splitlines() if line.startswith("gave up after"))
    assert "the robot: robot mode DISCONNECTED" in gave_up
    assert "last heard" in gave_up and "robot mode RUNNING" in gave_up, gave_up


def test_ur_rtde_errors_are_said_in_our_words() -> None:
    assert ur_words(RuntimeError("Timeout connecting to UR dashboard server.")) == (
        "the controller's dashboard does not answer: is the robot on, and is this its address?"
    )
    lost = ur_words(RuntimeError("RTDEControlInterface Exception: End of file"))
    assert lost == "the controller closed the connection"
    assert "Please" not in ur_words(RuntimeError("ur_rtde: Please enable remote control!"))
    refused = "Unlock protective stop failure: Cannot unlock protective stop until 5s after"
    assert ur_words(RuntimeError(refused)).startswith("not yet:")
    assert ur_words(URError("ours")) == "ours"  # our own words stay
    unknown = ur_words(RuntimeError("boost::asio weirdness 0x7f"))
    assert "0x7f" not in unknown and "RuntimeError" in unknown


@pytest.mark.sim
def test_a_refused_unlock_is_said_in_our_words(start_emulator, connect) -> None:
    emulator = start_emulator(unlock_delay=30.0)
    connection, _ = connect(emulator)
    emulator.protective_stop()
    assert wait_for(lambda: connection.state.safety_mode == 3)
    with pytest.raises(URError) as refused:
        connection.call(connection.clear_protective_stop)
    assert "not yet" in str(refused.value) and "Always inspect" not in str(refused.value)
    pendant = dashboard_client.DashboardClient(emulator.host)
    pendant.connect()
    pendant.disconnect()


@pytest.mark.sim
def test_costar_run_says_a_protective_stop_and_how_to_clear_it_then_gives_up(
    tmp_path: Path, start_emulator
) -> None:
    cell = tmp_path / "emulated.cell.json"
    emulator = start_emulator(write_cell=cell)
    out, err = io.StringIO(), io.StringIO()
    plan = _plan_file(tmp_path, (0.9,), 0.3)

    def stop_it() -> None:
        assert wait_for(lambda: emulator.state()["moving"], 30)
        emulator.protective_stop()

    import threading

    threading.Thread(target=stop_it, daemon=True).start()
    args = ["run", str(plan), "--cell", str(cell), "--hold-timeout", "1.5", "--timeout", "60"]
    code = main(args, out, err)
    text = out.getvalue()
    assert code == 3, text + err.getvalue()
    held = next(line for line in text.splitlines() if "held: protective stop" in line)
    assert "safety mode PROTECTIVE_STOP" in held and "clear it on the pendant" in held, held
    assert "gives up after 1.5 s" in held
    assert "gave up after 2 s held: protective stop" in text
