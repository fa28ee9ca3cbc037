"""The emulated dashboard server's answers (one line per command, as PolyScope gives them)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capabilities.ur.modes import RobotMode, SafetyMode

if TYPE_CHECKING:
    from capabilities.ur_emulator.controller import EmulatedController

__all__ = ["dashboard_reply"]


def _version_line(ctl: EmulatedController) -> str:
    major, minor, bugfix, build = ctl.version
    return f"URSoftware {major}.{minor}.{bugfix}.{build} (Jan 01 2024)"


def dashboard_reply(ctl: EmulatedController, command: str) -> tuple[str, bool]:
    """The reply to one dashboard command, and whether the server then closes the connection."""
    cmd = command.lower()
    running = ctl.program_running()
    simple = {
        "polyscopeversion": _version_line(ctl),
        "robotmode": f"Robotmode: {RobotMode(ctl.robot_mode).name}",
        "safetystatus": f"Safetystatus: {SafetyMode(ctl.safety_mode).name}",
        "safetymode": f"Safetymode: {SafetyMode(ctl.safety_mode).name}",
        "programstate": "PLAYING rtde_control" if running else "STOPPED <unnamed>",
        "running": f"Program running: {str(running).lower()}",
        "is in remote control": "true",
        "get serial number": "20235500000",
        "get robot model": "UR5",
        "get loaded program": "No program loaded",
        "isprogramsaved": "true <unnamed>",
        "close popup": "closing popup",
        "close safety popup": "closing safety popup",
        "restart safety": "Restarting safety",
    }
    if cmd in simple:
        return simple[cmd], False
    if cmd == "power on":
        return ctl.power_on(), False
    if cmd == "power off":
        ctl.power_off()
        return "Powering off", False
    if cmd == "brake release":
        return ctl.brake_release(), False
    if cmd == "unlock protective stop":
        return ctl.unlock_protective_stop(), False
    if cmd == "stop":
        if not running:
            return "Failed to execute: stop", False
        ctl.end_program("stopped from the dashboard")
        return "Stopped", False
    if cmd in ("quit", "shutdown"):
        return "Disconnected", True
    if cmd.startswith(("addtolog", "popup", "setuserrole")):
        return "Added log message" if cmd.startswith("addtolog") else "showing popup", False
    return f"could not understand: '{command}'", False
