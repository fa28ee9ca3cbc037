"""The robot and camera checks of `costar doctor --cell` against the emulator."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capabilities.recorded_frames import FrameRecorder
from capabilities.ur.doctor import cell_checks
from tests.capabilities.test_recorded_frames import _frame
from tests.capabilities.ur.emulators import wait_for


def _by_name(checks: list) -> dict:
    return {check.name: check for check in checks}


@pytest.mark.sim
def test_a_ready_emulated_cell_passes_and_a_powered_off_one_says_why(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    data = json.loads(cell_file.read_text("utf-8"))
    FrameRecorder(tmp_path / "frames", "shoulder").add(_frame())
    data["cameras"]["shoulder"]["source"] = {"kind": "recorded", "path": "frames"}
    cell_file.write_text(json.dumps(data), "utf-8")
    checks = _by_name(cell_checks(str(cell_file)))
    assert all(check.ok for check in checks.values()), checks
    assert set(checks) == {
        "cell file", "robot connection", "robot model", "robot ready", "remote control",
        "Robotiq gripper", "camera shoulder",
    }  # fmt: skip
    assert "PolyScope 5.12" in checks["robot connection"].detail
    emulator.power_off()
    assert wait_for(lambda: emulator.state()["robot_mode"] == 3)
    checks = _by_name(cell_checks(str(cell_file)))
    assert not checks["robot ready"].ok and "powered off" in checks["robot ready"].detail


def test_a_dead_host_and_a_broken_file_are_named(tmp_path: Path) -> None:
    bad = tmp_path / "bad.cell.json"
    bad.write_text('{"format_version": 2, "robot": {"kind": "ur"}}', "utf-8")
    (check,) = cell_checks(str(bad))
    assert not check.ok and "$.robot.host" in check.detail
    dead = tmp_path / "dead.cell.json"
    dead.write_text(
        json.dumps({"format_version": 2, "robot": {"kind": "ur", "host": "127.0.0.1"}}), "utf-8"
    )
    checks = _by_name(cell_checks(str(dead), connect_timeout=5.0))
    assert not checks["robot connection"].ok and "127.0.0.1" in checks["robot connection"].detail


@pytest.mark.sim
def test_a_cb3_controller_in_an_e_series_file_is_the_wrong_model(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "cb3.cell.json"
    start_emulator("3.15", write_cell=cell_file)
    data = json.loads(cell_file.read_text("utf-8"))
    assert data["robot"]["model"] == "UR5 CB3"
    data["robot"]["model"] = "UR5e"
    cell_file.write_text(json.dumps(data), "utf-8")
    checks = _by_name(cell_checks(str(cell_file)))
    model = checks["robot model"]
    assert not model.ok and "UR5e" in model.detail and "3.15" in model.detail
    assert "no remote control mode" in checks["remote control"].detail
