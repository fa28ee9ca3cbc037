"""The robot and camera checks of ``costar doctor --cell FILE``.

:func:`cell_checks` reads a cell file and, for a UR cell, asks the controller what an operator
would check on the pendant (reachable, PolyScope version against the model, robot mode, safety
mode, remote control, the control script), the gripper's URCap, and every camera for a frame.
Each check says what it found in words; nothing moves. (``costar doctor --cell FILE`` runs them after
the checks of the computer.)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from capabilities.check_result import CheckResult
from capabilities.errors import CapabilityError

if TYPE_CHECKING:
    from capabilities.robot.cell_file import CellConfig
    from capabilities.ur.connection import URConnection

__all__ = ["cell_checks"]


def cell_checks(path: str, connect_timeout: float = 10.0) -> list[CheckResult]:
    """The checks of one cell file (a simulated cell gets the file and camera checks only)."""
    from capabilities.robot.cell_file import CellConfig, CellConfigError

    try:
        config = CellConfig.load(path)
    except CellConfigError as exc:
        return [CheckResult("cell file", False, str(exc))]
    checks = [
        CheckResult("cell file", True, f"{path}: format_version 2, robot {config.robot.kind}")
    ]
    if config.robot.kind == "ur":
        checks += _robot_checks(config, connect_timeout)
    checks += [
        _camera_check(config, name) for name, c in config.cameras.items() if c.source != "sim"
    ]
    return checks


def _robot_checks(config: CellConfig, timeout: float) -> list[CheckResult]:
    from capabilities.ur.connection import URConnection, fault_reason

    robot = config.robot
    connection = URConnection(robot.host)
    try:
        connection.open(timeout)
    except CapabilityError as exc:
        return [CheckResult("robot connection", False, f"{exc}")]
    try:
        state = connection.state
        version = ".".join(map(str, connection.version))
        expected = 3 if robot.model == "UR5 CB3" else 5
        checks = [
            CheckResult("robot connection", True, f"{robot.host} answers (PolyScope {version})"),
            CheckResult(
                "robot model",
                connection.version[0] == expected,
                f"the file says {robot.model}, which runs PolyScope {expected}; "
                f"the controller runs {version}",
            ),
            CheckResult(
                "robot ready",
                not fault_reason(state),
                fault_reason(state) or "running, safety normal, control script running",
            ),
            _ask("remote control", lambda: _remote_control(connection)),
        ]
        if robot.tool.kind == "robotiq":
            checks.append(_ask("Robotiq gripper", lambda: _gripper(connection)))
        return checks
    finally:
        connection.close()


def _ask(name: str, probe: Callable[[], str]) -> CheckResult:
    """A check whose probe returns what it found, or raises why it failed."""
    try:
        return CheckResult(name, True, probe())
    except Exception as exc:  # the probe's failure is the finding
        return CheckResult(name, False, str(exc))


def _remote_control(connection: URConnection) -> str:
    """e-Series controllers take commands from the network only in remote control."""
    if connection.version[0] < 5:
        return "a CB3 controller has no remote control mode: nothing to check"
    if not connection.call(lambda: bool(connection.dashboard.isInRemoteControl())):
        raise CapabilityError(
            "the robot is in local control: switch it to remote control on the pendant"
        )
    return "in remote control"


def _gripper(connection: URConnection) -> str:
    from capabilities.ur.robotiq import RobotiqGripper

    RobotiqGripper(connection)  # activates the gripper, or raises why it cannot
    return "the URCap answers and the gripper is active"


def _camera_check(config: CellConfig, name: str) -> CheckResult:
    from capabilities.camera_sources import open_source

    settings = config.cameras[name]
    what = f"camera {name}"
    try:
        camera = open_source(name, settings.source, settings.where, config.folder())
        frame = camera.capture()
    except CapabilityError as exc:
        return CheckResult(what, False, str(exc))
    height, width = frame.depth.shape
    valid = float(np.isfinite(frame.depth).mean())
    ok = frame.rgb.shape[:2] == (height, width) and frame.K[0, 0] > 0 and valid > 0.1
    return CheckResult(
        what, ok, f"{settings.source}: {width}x{height}, depth on {valid:.0%} of the pixels"
    )
