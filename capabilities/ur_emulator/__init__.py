"""A loopback UR controller backed by the simulated cell, for ur_rtde without a robot.

It serves the dashboard (29999), the script port (30003), RTDE (30004) and the Robotiq
gripper URCap's socket (63352) on a loopback address, speaks ur_rtde's register handshake (the command registers are interpreted, the
URScript is not) and moves the simulated arm. Faults can be injected from a test or the
command line. Example::

    with UREmulator("127.0.0.2", version="5.12") as emulator:
        control = rtde_control.RTDEControlInterface("127.0.0.2")
        ...
        emulator.protective_stop()
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Self

from capabilities.camera_source import CameraSource
from capabilities.cell_features import ClosesOnExit
from capabilities.sim.cell import SimCell
from capabilities.stream_camera import FRAME_PORT, serve_frames
from capabilities.ur_emulator.controller import VERSIONS, EmulatedController
from capabilities.ur_emulator.errors import EmulatorError
from capabilities.ur_emulator.robotiq import ROBOTIQ_PORT, robotiq_client
from capabilities.ur_emulator.servers import (
    Server,
    check_loopback,
    dashboard_client,
    rtde_client,
    script_client,
)
from engine.types import Pose

__all__ = ["UREmulator", "VERSIONS", "DASHBOARD_PORT", "SCRIPT_PORT", "RTDE_PORT", "ROBOTIQ_PORT"]

DASHBOARD_PORT, SCRIPT_PORT, RTDE_PORT = 29999, 30003, 30004


class UREmulator(ClosesOnExit):
    """The loopback UR controller (with a Robotiq gripper's URCap); a context manager.

    Args:
        host: a loopback address (127.0.0.0/8); anything else is refused.
        version: the PolyScope version to answer as: "3.15", "5.9" or "5.12".
        cell: the simulated cell to drive (default: a new one, closed with the emulator).
        speed: real-time factor of a new cell (1.0: a real robot's pace).
        unlock_delay: seconds after a protective stop before the dashboard unlocks it.
        cameras: the simulated cell's cameras, served on ``FRAME_PORT`` (none: no server).
        truth: GROUND TRUTH of an object's pose by name (a scene's), for tests only.
    """

    def __init__(
        self,
        host: str = "127.0.0.2",
        version: str = "5.12",
        cell: SimCell | None = None,
        speed: float | None = 1.0,
        unlock_delay: float = 5.0,
        cameras: Mapping[str, CameraSource] | None = None,
        truth: Callable[[str], Pose] | None = None,
    ) -> None:
        self.host = check_loopback(host)
        self._cameras = dict(cameras or {})
        self.truth = truth
        if version not in VERSIONS:
            raise ValueError(f"version must be one of {sorted(VERSIONS)}, got {version!r}")
        self._own_cell = cell is None
        # The arm alone: no camera draws its world.
        self.cell = cell if cell is not None else SimCell(speed=speed, drawn=False)
        self.controller: EmulatedController | None = None
        self._servers: list[Server] = []
        self._version = version
        self._unlock_delay = unlock_delay

    # ---------------------------------------------------------------- lifecycle

    def start(self) -> UREmulator:
        """Start the cell (if owned), the controller and the three servers."""
        if self._own_cell:
            self.cell.start()
        try:
            self.controller = EmulatedController(self.cell, self._version, self._unlock_delay)
            self.controller.start()
            for port, handler in (
                (DASHBOARD_PORT, dashboard_client),
                (SCRIPT_PORT, script_client),
                (RTDE_PORT, rtde_client),
                (ROBOTIQ_PORT, robotiq_client),
            ):
                self._servers.append(Server(self.host, port, self.controller, handler))
            if self._cameras:
                frames = serve_frames(self._cameras)
                self._servers.append(Server(self.host, FRAME_PORT, self.controller, frames))
        except BaseException:
            self.close()
            raise
        return self

    def close(self) -> None:
        """Stop serving (clients see the connection closed) and stop the cell if owned.

        Idempotent; this is also the "killed controller" fault.
        """
        servers, self._servers = self._servers, []
        for server in servers:
            server.close()
        if self.controller is not None:
            self.controller.close()
        if self._own_cell:
            self.cell.close()

    kill = close

    def __enter__(self) -> Self:
        self.start()
        return self

    # ---------------------------------------------------------------- faults

    @property
    def ctl(self) -> EmulatedController:
        if self.controller is None:
            raise RuntimeError("the emulator is not started")
        return self.controller

    def protective_stop(
        self, at: float | None = None, on_contact: bool = False, lag: float = 0.0
    ) -> None:
        """A protective stop now, at simulated time ``at``, or (armed) on the arm's next contact;
        with ``lag``, the program's end is published that many s before the safety mode.
        """
        if on_contact:
            self.ctl.faults.stop_on_contact(True)
        elif at is not None:
            self.ctl.faults.stop_at(at)
        else:
            self.ctl.protective_stop("injected", lag=lag)

    def unlock(self) -> None:
        """The operator unlocks a protective stop on the pendant (the dashboard's command).

        Raises:
            EmulatorError: refused: earlier than the unlock delay after the stop.
        """
        reply = self.ctl.unlock_protective_stop()
        if reply.startswith("Cannot"):
            raise EmulatorError(reply)

    def emergency_stop(self) -> None:
        self.ctl.emergency_stop()

    def release_emergency_stop(self) -> None:
        self.ctl.release_emergency_stop()

    def power_off(self) -> None:
        self.ctl.power_off()

    def kill_script(self) -> None:
        """The control script stops (as after a script error); safety stays normal."""
        self.ctl.end_program("the control script died")

    def disconnect(self, outage: float = 1.0) -> None:
        """Close every client connection, as a network outage of ``outage`` s does: the
        servers keep listening, but close what connects before it is over.

        A real outage lasts longer than ur_rtde's first attempt to reconnect, made on its
        own thread at once; ur_rtde 1.6.5 aborts the process when that attempt succeeds
        (its reconnect replaces the running receive thread's handle), so an emulated drop
        that lets it succeed would test what a cell does not meet.
        """
        for server in self._servers:
            server.drop_clients(outage)
