"""UR controller codes as RTDE and the dashboard report them (shared by backend and emulator)."""

from __future__ import annotations

from enum import IntEnum

__all__ = ["RobotMode", "RuntimeState", "SafetyMode", "PolyScopeVersion", "parse_version"]


class RobotMode(IntEnum):
    """RTDE ``robot_mode``."""

    NO_CONTROLLER = -1
    DISCONNECTED = 0
    CONFIRM_SAFETY = 1
    BOOTING = 2
    POWER_OFF = 3
    POWER_ON = 4
    IDLE = 5
    BACKDRIVE = 6
    RUNNING = 7
    UPDATING_FIRMWARE = 8


class SafetyMode(IntEnum):
    """RTDE ``safety_mode``."""

    NORMAL = 1
    REDUCED = 2
    PROTECTIVE_STOP = 3
    RECOVERY = 4
    SAFEGUARD_STOP = 5
    SYSTEM_EMERGENCY_STOP = 6
    ROBOT_EMERGENCY_STOP = 7
    VIOLATION = 8
    FAULT = 9
    VALIDATE_JOINT_ID = 10
    UNDEFINED_SAFETY_MODE = 11
    AUTOMATIC_MODE_SAFEGUARD_STOP = 12
    SYSTEM_THREE_POSITION_ENABLING_STOP = 13


class RuntimeState(IntEnum):
    """RTDE ``runtime_state`` (the program's state)."""

    STOPPING = 0
    STOPPED = 1
    PLAYING = 2
    PAUSING = 3
    PAUSED = 4
    RESUMING = 5


PolyScopeVersion = tuple[int, int]


def parse_version(text: str) -> PolyScopeVersion:
    """(major, minor) from "5.12", "5.12.0.1101534" or a dashboard line that contains one.

    Raises:
        ValueError: no version in ``text``.
    """
    import re

    match = re.search(r"(\d+)\.(\d+)", text)
    if match is None:
        raise ValueError(f"no PolyScope version in {text!r} (expected e.g. 5.12)")
    return int(match.group(1)), int(match.group(2))
