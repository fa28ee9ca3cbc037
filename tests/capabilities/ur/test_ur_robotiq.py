"""The Robotiq gripper through its URCap socket (63352), against the emulator's simulated gripper."""

from __future__ import annotations

import socket

import pytest

from capabilities.ur.errors import URError
from capabilities.ur.robotiq import ROBOTIQ_PORT, RobotiqGripper
from tests.capabilities.ur.emulators import FAST

pytestmark = pytest.mark.sim


def _ask(sock: socket.socket, line: str) -> str:
    sock.sendall(line.encode() + b"\n")
    reply = b""
    while not reply.endswith(b"\n"):
        reply += sock.recv(256)
    return reply.decode().strip()


def test_the_urcap_protocol_activates_moves_and_reports(start_emulator) -> None:
    emulator = start_emulator("5.12")
    with socket.create_connection((emulator.host, ROBOTIQ_PORT), timeout=5) as sock:
        assert _ask(sock, "GET STA") == "STA 0"
        assert _ask(sock, "SET POS 255 GTO 1") == "ack"  # not active: nothing moves
        assert emulator.state()["gripper_closed"] is False
        assert _ask(sock, "SET ACT 1") == "ack"
        assert _ask(sock, "GET STA") == "STA 3"
        assert _ask(sock, "SET POS 255 SPE 255 FOR 150 GTO 1") == "ack"
        assert _ask(sock, "GET PRE") == "PRE 255"
        assert _ask(sock, "GET OBJ") in ("OBJ 0", "OBJ 3")
        for bad in ("SET POS 300", "SET NOPE 1", "GET NOPE", "HELLO", "SET POS x"):
            assert _ask(sock, bad) == "?", bad


def test_the_gripper_backend_closes_and_opens_the_emulated_gripper(start_emulator, connect) -> None:
    emulator = start_emulator("5.12", speed=FAST)  # the fingers' moves only have to end
    connection, _ = connect(emulator)
    gripper = RobotiqGripper(connection)
    handle = gripper.close()
    assert handle.wait(15) and handle.ok, handle.message
    assert gripper.is_closed() and emulator.state()["gripper_closed"] is True
    assert not gripper.is_holding()  # nothing between the fingers
    handle = gripper.open()
    assert handle.wait(15) and handle.ok, handle.message
    assert not gripper.is_closed() and emulator.state()["gripper_closed"] is False


def test_no_urcap_is_a_clear_error(start_emulator, connect) -> None:
    emulator = start_emulator("5.12")
    connection, _ = connect(emulator)
    with pytest.raises(URError, match=r"no Robotiq URCap at 127\.[0-9.]+:1"):
        RobotiqGripper(connection, port=1)
