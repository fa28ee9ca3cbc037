"""The loopback UR controller with the unmodified ur_rtde library as its client."""

from __future__ import annotations

import dashboard_client
import pytest
import rtde_control
import rtde_io
import rtde_receive

from capabilities.ur_emulator import UREmulator
from capabilities.ur_emulator.errors import EmulatorError
from capabilities.ur_emulator.servers import check_loopback
from tests.capabilities.ur.emulators import FAST, wait_for

pytestmark = pytest.mark.sim


@pytest.mark.parametrize("host", ["192.168.1.5", "0.0.0.0", "localhost", "::1"])
def test_refuses_addresses_beyond_loopback(host: str) -> None:
    with pytest.raises(EmulatorError, match="loopback"):
        check_loopback(host)
    with pytest.raises(EmulatorError, match="loopback"):
        UREmulator(host)


def test_ur_rtde_connects_reads_and_moves(start_emulator) -> None:
    emulator = start_emulator("5.12", speed=FAST)  # a move that only has to end
    dashboard = dashboard_client.DashboardClient(emulator.host)
    dashboard.connect()
    assert dashboard.polyscopeVersion().startswith("5.12.")
    assert dashboard.robotmode() == "Robotmode: RUNNING"
    assert dashboard.safetystatus() == "Safetystatus: NORMAL"
    receive = rtde_receive.RTDEReceiveInterface(emulator.host)
    control = rtde_control.RTDEControlInterface(emulator.host)
    io = rtde_io.RTDEIOInterface(emulator.host)
    try:
        assert control.isProgramRunning()
        assert dashboard.programState().startswith("PLAYING")
        q = receive.getActualQ()
        assert q == pytest.approx(emulator.state()["q"], abs=1e-3)
        target = list(q)
        target[0] += 0.15
        assert control.moveJ(target, 1.0, 1.4)  # blocking: returns when the arm arrived
        assert receive.getActualQ() == pytest.approx(target, abs=2e-3)
        assert io.setToolDigitalOut(0, True)
        assert io.setStandardDigitalOut(2, True)
        assert wait_for(lambda: receive.getActualDigitalOutputBits() == (1 << 16) | (1 << 2))
        assert io.setSpeedSlider(0.5)
        assert wait_for(lambda: receive.getTargetSpeedFraction() == pytest.approx(0.5))
    finally:
        control.disconnect()
        io.disconnect()
        receive.disconnect()


def test_power_off_reads_zeros_and_refuses_moves(start_emulator) -> None:
    emulator = start_emulator("5.12")
    receive = rtde_receive.RTDEReceiveInterface(emulator.host)
    control = rtde_control.RTDEControlInterface(emulator.host)
    try:
        before = emulator.state()["q"]
        emulator.power_off()
        assert wait_for(lambda: receive.getRobotMode() == 3)  # POWER_OFF
        assert receive.getActualQ() == [0.0] * 6  # what a real UR reports with the arm off
        assert wait_for(lambda: not control.isProgramRunning())
        target = list(before)
        target[0] += 0.2
        assert control.moveJ(target, 1.0, 1.4) is False
        dashboard = dashboard_client.DashboardClient(emulator.host)
        dashboard.connect()
        assert dashboard.robotmode() == "Robotmode: POWER_OFF"
        dashboard.powerOn()
        dashboard.brakeRelease()
        assert wait_for(lambda: receive.getRobotMode() == 7)
        assert receive.getActualQ() == pytest.approx(before, abs=1e-3)
    finally:
        control.disconnect()
        receive.disconnect()


def test_freedrive_mode_is_a_no_op_before_5_10(start_emulator) -> None:
    """Why the backend falls back: on 3.15 ur_rtde's script drops freedrive_mode silently."""
    emulator = start_emulator("3.15")
    control = rtde_control.RTDEControlInterface(emulator.host)
    try:
        assert control.freedriveMode() is True
        assert emulator.state()["freedrive"] is False
        assert control.teachMode() is True
        assert emulator.state()["freedrive"] is True
        assert control.endTeachMode() is True
    finally:
        control.disconnect()
