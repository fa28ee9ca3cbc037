"""The UR arm backend (capabilities.ur.arm) against the loopback emulator through ur_rtde."""

from __future__ import annotations

import math

import pytest

from capabilities.jobs import job_from_handle
from capabilities.ur.connection import fault_reason
from capabilities.ur.errors import URError
from capabilities.ur.modes import RobotMode
from capabilities.ur.tool_io import DigitalPin, URSuctionCup
from engine.error_types import ErrorType
from engine.types import Pose
from tests.capabilities.ur.emulators import FAST, wait_for

pytestmark = pytest.mark.sim


def test_connect_read_move_joints_and_linear(start_emulator, connect) -> None:
    emulator = start_emulator("5.12", speed=FAST)  # moves that only have to end
    connection, arm = connect(emulator)
    assert connection.version == (5, 12)
    q = arm.joint_positions()
    assert q == pytest.approx(emulator.state()["q"], abs=1e-3)
    target = list(q)
    target[0] += 0.2
    handle = arm.move_joints(target, 1.0, 1.4)
    assert handle.wait(20), "moveJ did not finish"
    assert handle.ok, handle.message
    assert emulator.state()["q"] == pytest.approx(target, abs=0.01)

    start = arm.tcp_pose()
    goal = Pose((start.position[0], start.position[1], start.position[2] - 0.05), start.orientation)
    handle = arm.move_linear(goal, 0.25, 1.2)
    assert handle.wait(20) and handle.ok, handle.message
    assert math.dist(arm.tcp_pose().position, goal.position) < 0.002


def test_a_halted_move_stops_the_arm(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    _, arm = connect(emulator)
    q = arm.joint_positions()
    far = list(q)
    far[0] += 1.5
    handle = arm.move_joints(far, 0.5, 1.0)
    assert wait_for(lambda: abs(emulator.state()["q"][0] - q[0]) > 0.02), "the arm never moved"
    handle.cancel()
    assert handle.wait(10)
    assert handle.ok is False and "halted" in handle.message
    assert wait_for(lambda: not emulator.state()["moving"]), "the arm did not stop"
    stopped = emulator.state()["q"][0]
    assert abs(stopped - far[0]) > 0.3  # it stopped on the way, not at the target


def test_freedrive_falls_back_to_teach_mode_on_3_15(start_emulator, connect) -> None:
    emulator = start_emulator("3.15")
    connection, arm = connect(emulator)
    assert connection.version == (3, 15)
    arm.set_freedrive(True)
    assert arm.freedrive_active()
    assert emulator.state()["freedrive"] is True  # teachMode: freedriveMode is a no-op there
    with pytest.raises(URError, match=r"getFreedriveStatus.*needs PolyScope 5\.10.*runs 3\.15"):
        arm.freedrive_status()
    arm.set_freedrive(False)
    assert emulator.state()["freedrive"] is False


def test_freedrive_mode_on_5_12(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    _, arm = connect(emulator)
    arm.set_freedrive(True)
    assert emulator.state()["freedrive"] is True
    assert arm.freedrive_status() == 1
    arm.set_freedrive(False)
    assert emulator.state()["freedrive"] is False


def test_power_off_gives_no_move_and_no_zero_pose(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    connection, arm = connect(emulator)
    before = emulator.state()["q"]
    emulator.power_off()
    assert wait_for(lambda: connection.state.robot_mode == RobotMode.POWER_OFF)
    with pytest.raises(URError, match="not running"):
        arm.joint_positions()
    with pytest.raises(URError, match="not running"):
        arm.tcp_pose()
    target = list(before)
    target[0] += 0.3
    handle = arm.move_joints(target, 1.0, 1.4)
    assert handle.wait(10)
    assert handle.ok is False and "powered off" in handle.message
    assert emulator.state()["q"] == [0.0] * 6  # the controller reports zeros with the arm off


def test_protective_stop_during_a_move_fails_it(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    connection, arm = connect(emulator)
    q = arm.joint_positions()
    far = list(q)
    far[0] += 1.5
    handle = arm.move_joints(far, 0.5, 1.0)
    assert wait_for(lambda: abs(emulator.state()["q"][0] - q[0]) > 0.02)
    emulator.protective_stop()
    assert handle.wait(10)
    assert handle.ok is False and "protective stop" in handle.message
    assert job_from_handle(handle).error is ErrorType.PROTECTIVE_STOP  # a Catch can take it
    again = arm.move_joints(q, 0.5, 1.0)
    assert again.wait(10) and again.ok is False and "protective stop" in again.message
    # The operator clears it: unlock, and the control script is uploaded again.
    connection.call(connection.clear_protective_stop)
    # The arm moves again once the script runs and the safety mode read back is normal (a
    # loaded machine may see the script before the next RTDE frame says so).
    assert wait_for(lambda: connection.state.program_running and not fault_reason(connection.state))
    back = arm.move_joints(q, 1.0, 1.4)
    assert back.wait(20) and back.ok, back.message


def test_a_killed_controller_mid_move_is_connection_lost(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    _, arm = connect(emulator)
    q = arm.joint_positions()
    far = list(q)
    far[0] += 1.5
    handle = arm.move_joints(far, 0.5, 1.0)
    assert wait_for(lambda: abs(emulator.state()["q"][0] - q[0]) > 0.02)
    emulator.kill()
    assert handle.wait(30), "the move never noticed the controller was gone"
    assert handle.ok is False and "connection lost" in handle.message
    assert job_from_handle(handle).error is ErrorType.CONNECTION_LOST
    with pytest.raises(URError, match="connection lost"):
        arm.joint_positions()


def test_suction_cup_on_a_tool_digital_output(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    connection, _ = connect(emulator)
    cup = URSuctionCup(connection, DigitalPin("tool", 0))
    handle = cup.suction_on()
    assert handle.wait(10) and handle.ok, handle.message
    assert cup.vacuum_on() and cup.has_part()
    assert emulator.state()["digital_outputs"] == 1 << 16
    handle = cup.suction_off()
    assert handle.wait(10) and handle.ok, handle.message
    assert not cup.vacuum_on()
    with pytest.raises(URError, match="no holster"):
        cup.handle_grasp_pose()
    with pytest.raises(ValueError, match="tool 0-1"):
        DigitalPin("tool", 2)


def test_speed_slider_scales_the_emulated_arm(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    _, arm = connect(emulator)
    handle = arm.set_speed_fraction(0.4)
    assert handle.wait(10) and handle.ok, handle.message
    assert wait_for(lambda: emulator.state()["speed_fraction"] == pytest.approx(0.4))
    bad = arm.set_speed_fraction(1.5)
    assert bad.done() and bad.ok is False and "0..1" in bad.message


def test_protective_stop_at_a_set_time(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    _, arm = connect(emulator)
    q = arm.joint_positions()
    far = list(q)
    far[0] += 1.5
    emulator.protective_stop(at=emulator.state()["sim_time"] + 0.3)
    handle = arm.move_joints(far, 0.5, 1.0)
    assert handle.wait(20)
    assert handle.ok is False and "protective stop" in handle.message
    assert abs(emulator.state()["q"][0] - far[0]) > 0.3


def test_dead_script_then_emergency_stop_fail_moves_by_name(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    connection, arm = connect(emulator)
    q = arm.joint_positions()
    far = list(q)
    far[0] += 1.5
    handle = arm.move_joints(far, 0.5, 1.0)
    assert wait_for(lambda: abs(emulator.state()["q"][0] - q[0]) > 0.02)
    emulator.kill_script()
    assert handle.wait(10)
    assert handle.ok is False and "control script is not running" in handle.message
    connection.call(connection.start_control)  # upload the script again
    assert connection.state.program_running
    handle = arm.move_joints(q, 0.5, 1.0)
    assert wait_for(lambda: emulator.state()["moving"])
    emulator.emergency_stop()
    assert handle.wait(10)
    assert handle.ok is False and "emergency stop" in handle.message
    assert job_from_handle(handle).error is ErrorType.EMERGENCY_STOP
