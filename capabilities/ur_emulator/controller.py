"""The emulated UR controller: modes, registers, I/O and the arm of a simulated cell.

One controller thread runs the cycle (500 Hz on e-Series versions, 125 Hz on CB3): it runs the
control program (see ``program.py``) and publishes a snapshot of every RTDE output that the
RTDE connections stream. The servers (``servers.py``) change the controller through the
methods here; every method may be called from any thread.
"""

from __future__ import annotations

import logging
import select
import socket
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from ur_analytic_ik import ur5

from capabilities.geometry import matrix_to_pose, pose_to_matrix
from capabilities.robot.commands import CommandHandle
from capabilities.sim.cell import SimCell
from capabilities.ur.frames import matrix_from_rotvec_pose, rotvec_pose_from_matrix
from capabilities.ur.modes import RobotMode, RuntimeState, SafetyMode
from capabilities.ur_emulator.faults import ContactWatch
from capabilities.ur_emulator.loops import next_cycle
from capabilities.ur_emulator.program import ControlProgram
from capabilities.ur_emulator.robotiq import RobotiqURCap
from capabilities.ur_emulator.wire import OUTPUT_TYPES, output_type

__all__ = ["EmulatedController", "VERSIONS"]

_log = logging.getLogger(__name__)

# PolyScope versions the emulator answers as: (major, minor, bugfix, build).
VERSIONS: dict[str, tuple[int, int, int, int]] = {
    "3.15": (3, 15, 7, 106331),
    "5.9": (5, 9, 4, 1031232),
    "5.12": (5, 12, 0, 1101534),
}
_ZEROS6 = (0.0,) * 6
# s a control script that takes the robot from another client's waits before it runs (a UR
# loading a program): the first client sees its script end.
TAKEOVER_START = 0.3
_SAFETY_BIT = {
    SafetyMode.NORMAL: 0,
    SafetyMode.REDUCED: 1,
    SafetyMode.PROTECTIVE_STOP: 2,
    SafetyMode.RECOVERY: 3,
    SafetyMode.SAFEGUARD_STOP: 4,
    SafetyMode.SYSTEM_EMERGENCY_STOP: 5,
    SafetyMode.ROBOT_EMERGENCY_STOP: 6,
    SafetyMode.VIOLATION: 8,
    SafetyMode.FAULT: 9,
}
_EMERGENCY = (SafetyMode.ROBOT_EMERGENCY_STOP, SafetyMode.SYSTEM_EMERGENCY_STOP)
BLOCKED = "blocked"  # how the simulated arm's move that could not reach its target ends
DEVIATES = "position deviates from path"  # PolyScope's popup for a blocked move


class EmulatedController:
    """The controller state and its cycle.

    Args:
        cell: the simulated cell whose arm this controller drives (started).
        version: "3.15", "5.9" or "5.12".
        unlock_delay: seconds after a protective stop before it can be unlocked (5 on a UR).
    """

    def __init__(self, cell: SimCell, version: str = "5.12", unlock_delay: float = 5.0) -> None:
        if version not in VERSIONS:
            raise ValueError(f"version must be one of {sorted(VERSIONS)}, got {version!r}")
        self.cell = cell
        self.version = VERSIONS[version]
        self.frequency = 500.0 if self.version[0] >= 5 else 125.0
        self.unlock_delay = unlock_delay
        self._lock = threading.RLock()
        self._inputs: dict[str, Any] = {}
        self._input_stamps: dict[str, float] = {}  # when each input was last written
        self._input_sockets: set[socket.socket] = set()  # the RTDE clients' connections
        self._out_int = [0] * 48
        self._out_double = [0.0] * 48
        self.robot_mode = RobotMode.RUNNING
        self.safety_mode = SafetyMode.NORMAL
        self._program: ControlProgram | None = None
        self._pending_script: int | None = None  # reg offset of an uploaded script
        self._start_after = 0.0  # monotonic time before which the pending script waits
        # The script-port clients that uploaded a control script, and the one whose script
        # runs (or ran last): a second client's script takes the robot from the first's.
        self.script_clients: set[int] = set()
        self._connected_script_clients: set[int] = set()
        self._owner: int | None = None
        self.takeovers = 0
        self._lagging_stop = False  # a protective stop whose safety mode is still on its way
        self._stopped_at = 0.0
        self.freedrive_on = False
        self._tcp = np.eye(4)
        self._digital_out = 0  # bits 0-7 standard, 8-15 configurable, 16-17 tool
        self._digital_in = 0  # likewise, set by the test or the command line (a pedal)
        self.teach_button = False
        self.speed_fraction = 1.0
        self.messages: list[str] = []
        self.popup = ""  # the safety popup shown on the pendant ("" when none)
        self._started = time.monotonic()
        self._base = pose_to_matrix(cell.config.robot_base)
        self._base_inv = np.linalg.inv(self._base)
        self.faults = ContactWatch(cell, self)
        self.robotiq = RobotiqURCap(self)
        self._snapshot: dict[str, Any] = {}
        self._stop_event = threading.Event()
        self._thread = threading.Thread(target=self._run, name="ur-emulator-ctl", daemon=True)
        self._publish()

    # ---------------------------------------------------------------- lifecycle

    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop_event.set()
        if self._thread.is_alive():
            self._thread.join()
        self.faults.close()
        with self._lock:
            self._end_program_locked("the controller shut down")

    def _run(self) -> None:
        period = 1.0 / self.frequency
        next_time = time.monotonic()
        while not self._stop_event.is_set():
            try:
                self._cycle()
            except Exception:  # the emulator must keep answering; log and go on
                _log.exception("emulated controller cycle failed")
            next_time = next_cycle(next_time, period, self._stop_event)

    def _cycle(self) -> None:
        with self._lock:
            if (
                self._pending_script is not None
                and self._can_run()
                and time.monotonic() >= self._start_after
            ):
                self._program = ControlProgram(self, self._pending_script)
                self._pending_script = None
            self.faults.check()
            collision = self.cell.robot.protective_stop()
            if (
                collision is not None
                and self.safety_mode == SafetyMode.NORMAL
                and not self._lagging_stop
            ):
                self.protective_stop(collision.cause)  # the arm hit something: as a UR does
            if self._program is not None and not self._program.step():
                self._end_program_locked("the control script ended")
            self._publish()

    # ---------------------------------------------------------------- snapshot

    def snapshot(self) -> dict[str, Any]:
        """The latest values of every RTDE output (replaced, never mutated)."""
        return self._snapshot

    def _publish(self) -> None:
        arm_on = self.robot_mode >= RobotMode.IDLE
        q = tuple(self.cell.robot.joint_positions()) if arm_on else _ZEROS6
        qd = tuple(self.cell.robot.joint_velocities()) if arm_on else _ZEROS6
        tcp = rotvec_pose_from_matrix(self._tcp_base(q)) if arm_on else list(_ZEROS6)
        running = self._program is not None
        status = (1 if self.robot_mode >= RobotMode.POWER_ON else 0) | (2 if running else 0)
        status |= 4 if self.teach_button else 0
        safety_bits = 1 << _SAFETY_BIT.get(self.safety_mode, 9)
        if self.safety_mode in _EMERGENCY:
            safety_bits |= 1 << 7
        if self.safety_mode != SafetyMode.NORMAL:
            safety_bits |= 1 << 10
        values: dict[str, Any] = {
            "timestamp": time.monotonic() - self._started,
            "actual_q": q,
            "target_q": q,
            "actual_qd": qd,
            "target_qd": qd,
            "actual_TCP_pose": tuple(tcp),
            "target_TCP_pose": tuple(tcp),
            "robot_mode": int(self.robot_mode),
            "safety_mode": int(self.safety_mode),
            "safety_status": int(self.safety_mode),
            "runtime_state": int(RuntimeState.PLAYING if running else RuntimeState.STOPPED),
            "robot_status_bits": status,
            "safety_status_bits": safety_bits,
            "speed_scaling": 1.0 if running else 0.0,
            "target_speed_fraction": self.speed_fraction,
            "actual_digital_output_bits": self._digital_out,
            "actual_digital_input_bits": self._digital_in,
            "joint_mode": (253 if arm_on else 236,) * 6,
            "actual_main_voltage": 48.0 if arm_on else 0.0,
        }
        for i, value in enumerate(self._out_int):
            values[f"output_int_register_{i}"] = value
        for i, fvalue in enumerate(self._out_double):
            values[f"output_double_register_{i}"] = fvalue
        self._snapshot = values

    @staticmethod
    def default_value(name: str) -> Any:
        """The zero of an output's type (for fields the emulator does not model)."""
        kind = output_type(name)
        if kind.startswith("VECTOR"):
            return (0,) * (3 if kind == "VECTOR3D" else 6)
        return 0.0 if kind == "DOUBLE" else 0

    # ---------------------------------------------------------------- inputs and outputs

    def write_inputs(self, values: dict[str, Any]) -> None:
        """Apply an RTDE input package (registers, digital outputs, speed slider)."""
        now = time.monotonic()
        with self._lock:
            self._inputs.update(values)
            self._input_stamps.update(dict.fromkeys(values, now))
            self._apply_masks(values)

    def input_silence(self, name: str, since: float) -> float:
        """Seconds since input ``name`` was last written (or since ``since``, if later)."""
        with self._lock:
            return time.monotonic() - max(self._input_stamps.get(name, since), since)

    def add_input_socket(self, conn: socket.socket, present: bool = True) -> None:
        """An RTDE client's connection starts (or, ``present`` False, ends)."""
        with self._lock:
            if present:
                self._input_sockets.add(conn)
            else:
                self._input_sockets.discard(conn)

    def inputs_pending(self) -> bool:
        """True while an RTDE client has sent bytes the emulator has not read yet: then a
        silence is the emulator's own delay (a loaded machine), not the client's.
        """
        with self._lock:
            conns = [c for c in self._input_sockets if c.fileno() >= 0]
        try:
            return bool(conns) and bool(select.select(conns, [], [], 0)[0])
        except (OSError, ValueError):  # closed meanwhile
            return False

    def _apply_masks(self, values: dict[str, Any]) -> None:
        for prefix, shift in (("standard", 0), ("configurable", 8), ("tool", 16)):
            mask = values.get(f"{prefix}_digital_output_mask")
            if mask:
                bits = int(values.get(f"{prefix}_digital_output", 0))
                self._digital_out = (self._digital_out & ~(mask << shift)) | (
                    (bits & mask) << shift
                )
        if values.get("speed_slider_mask"):
            self.speed_fraction = min(1.0, max(0.0, float(values["speed_slider_fraction"])))

    def input_value(self, name: str, default: Any) -> Any:
        with self._lock:
            return self._inputs.get(name, default)

    def set_output_int(self, index: int, value: int) -> None:
        with self._lock:
            self._out_int[index] = int(value)

    def set_output_double(self, index: int, value: float) -> None:
        with self._lock:
            self._out_double[index] = float(value)

    def set_digital_input(self, bit: int, level: bool) -> None:
        """Set one digital input (bit 0-7 standard, 8-15 configurable, 16-17 tool)."""
        with self._lock:
            self._digital_in = (
                (self._digital_in | (1 << bit)) if level else (self._digital_in & ~(1 << bit))
            )

    def press_teach_button(self, down: bool) -> None:
        """The pendant's teach button: held down, the arm is in freedrive, as on a UR."""
        with self._lock:
            if down and self._can_run() and not self.freedrive_on:
                self.set_freedrive(True)
            elif not down and self.teach_button:
                self.set_freedrive(False)
            self.teach_button = down

    def digital_outputs(self) -> int:
        """Bits 0-7 standard, 8-15 configurable, 16-17 tool digital outputs."""
        return self._digital_out

    def text(self, message: str) -> None:
        """A message the controller logs (what textmsg would show)."""
        _log.info("UR emulator: %s", message)
        self.messages.append(message)

    # ---------------------------------------------------------------- the program

    def _can_run(self) -> bool:
        return (
            self.robot_mode == RobotMode.RUNNING
            and self.safety_mode == SafetyMode.NORMAL
            and not self._lagging_stop
        )

    def script_client(self, client: int, connected: bool = True) -> None:
        """A script-port client connected (or, ``connected`` False, went away)."""
        with self._lock:
            if connected:
                self._connected_script_clients.add(client)
            else:
                self._connected_script_clients.discard(client)

    def load_script(self, reg_offset: int, client: int = 0) -> None:
        """The control script arrived on the script port: run it from the next cycle.

        A UR runs one program: the script of a client other than the one whose script runs
        (or ran last, stopped through the dashboard as ur_rtde does at its start, while that
        client is still connected) takes the robot from it. That is logged, and the new
        script starts after TAKEOVER_START s (a controller loading a program), so the first
        client sees its script end.
        """
        with self._lock:
            self.script_clients.add(client)
            previous = self._owner
            takeover = (
                previous is not None
                and previous != client
                and previous in self._connected_script_clients
            )
            self._end_program_locked("a new script replaces the running one")
            if takeover:
                self.takeovers += 1
                self.text(
                    f"script client {client}'s control script took the robot from script "
                    f"client {previous}'s ({len(self.script_clients)} clients uploaded one)"
                )
            self._start_after = time.monotonic() + (TAKEOVER_START if takeover else 0.0)
            if not self._can_run():
                self.text("script not started: the robot is not running or not in normal mode")
                return
            self._owner = client
            self._pending_script = reg_offset

    def program_running(self) -> bool:
        return self._program is not None

    def end_program(self, reason: str = "the program was stopped") -> None:
        with self._lock:
            self._end_program_locked(reason)

    def _end_program_locked(self, reason: str) -> None:
        self._pending_script = None
        if self._program is not None:
            self._program.end()
            self._program = None
            self.text(reason)
            # A program stop decelerates the arm to a halt, as a UR does (a move left to
            # the controller would otherwise go on to its target).
            self.cell.robot.stop(4.0)

    # ---------------------------------------------------------------- arm

    def _tcp_base(self, q: Sequence[float]) -> np.ndarray:
        return np.asarray(ur5.forward_kinematics(*[float(v) for v in q])) @ self._tcp

    def forward_kinematics(self, q: Sequence[float]) -> np.ndarray:
        """The TCP matrix in the base frame for joints ``q``."""
        return self._tcp_base(q)

    def inverse_kinematics(self, tcp_base: np.ndarray) -> tuple[float, ...] | None:
        world = self._world_tcp(tcp_base)
        return self.cell.robot.inverse_kinematics(matrix_to_pose(world))

    def _world_tcp(self, tcp_base: np.ndarray) -> np.ndarray:
        """The sim's TCP (its current tool) in the world for a controller TCP in the base."""
        flange = self._base @ tcp_base @ np.linalg.inv(self._tcp)
        return np.asarray(flange @ pose_to_matrix(self.cell.tcp_offset()))

    def move_joints(self, q: Sequence[float], speed: float, accel: float) -> CommandHandle:
        return self._watch(
            self.cell.robot.move_joints(list(q), speed * self.speed_fraction or 1e-3, accel)
        )

    def move_linear(self, tcp_base: np.ndarray, speed: float, accel: float) -> CommandHandle:
        target = matrix_to_pose(self._world_tcp(tcp_base))
        return self._watch(
            self.cell.robot.move_linear(target, speed * self.speed_fraction or 1e-3, accel)
        )

    def stop_arm(self, decel: float) -> CommandHandle:
        return self.cell.robot.stop(decel)

    def arm_moving(self) -> bool:
        return self.cell.robot.is_moving()

    def _watch(self, handle: CommandHandle) -> CommandHandle:
        """A move that fails on its own (unreachable, path error) ends the script, as on a UR;
        a collision is the arm's protective stop, which the next cycle raises instead.
        """

        def finished(h: CommandHandle) -> None:
            collided = self.cell.robot.protective_stop() is not None
            if h.ok or h.cancel_requested or collided:
                return
            if h.message.startswith(BLOCKED):
                # Held back short of its target: a UR's joints then deviate from the path it
                # planned, and its safety system makes a protective stop of it (a script
                # error would leave the arm pressing on whatever holds it).
                fault: Callable[[str], None] = self.protective_stop
                why = f"{DEVIATES} ({h.message})"
            else:
                fault, why = self.end_program, f"script error: {h.message}"
            threading.Thread(target=fault, args=(why,), daemon=True).start()

        handle.add_done_callback(finished)
        return handle

    def set_freedrive(self, on: bool) -> None:
        self.freedrive_on = on
        self.cell.robot.set_freedrive(on)

    def set_tcp(self, p: Sequence[float]) -> None:
        self._tcp = matrix_from_rotvec_pose(p)

    def tcp_rotvec(self) -> list[float]:
        return rotvec_pose_from_matrix(self._tcp)

    # ---------------------------------------------------------------- safety

    def protective_stop(self, reason: str = "protective stop", lag: float = 0.0) -> None:
        """Halt the arm, stop the program, safety mode PROTECTIVE_STOP.

        With ``lag`` the program's end is published ``lag`` s before the safety mode (a real
        controller's RTDE streams can tell the two apart by a few frames).
        """
        with self._lock:
            if self.safety_mode == SafetyMode.PROTECTIVE_STOP or self._lagging_stop:
                return
            if lag > 0:
                self._halt(f"protective stop: {reason}")
                self._lagging_stop = True
                self._publish()
                timer = threading.Timer(lag, self._stop_arrives, (reason,))
                timer.daemon = True
                timer.start()
                return
            self._set_protective_stop(reason)

    def _stop_arrives(self, reason: str) -> None:
        with self._lock:
            self._lagging_stop = False
            self._set_protective_stop(reason)

    def _set_protective_stop(self, reason: str) -> None:
        with self._lock:
            self._halt(f"protective stop: {reason}")
            # PolyScope's safety popup and log line; the dashboard's safetystatus says
            # PROTECTIVE_STOP until it is unlocked.
            self.popup = f"Protective stop: {reason}"
            self.text(self.popup)
            self.safety_mode = SafetyMode.PROTECTIVE_STOP
            self._stopped_at = time.monotonic()
            self._publish()

    def emergency_stop(self) -> None:
        """Emergency stop: the arm halts and powers off until released and powered on."""
        with self._lock:
            self._halt("emergency stop")
            self.safety_mode = SafetyMode.ROBOT_EMERGENCY_STOP
            self.robot_mode = RobotMode.POWER_OFF
            self._publish()

    def release_emergency_stop(self) -> None:
        """The operator releases the emergency stop button (power on is still needed)."""
        with self._lock:
            if self.safety_mode in _EMERGENCY:
                self.safety_mode = SafetyMode.NORMAL

    def power_off(self) -> None:
        with self._lock:
            self._halt("power off")
            self.robot_mode = RobotMode.POWER_OFF
            self._publish()

    def power_on(self) -> str:
        with self._lock:
            if self.safety_mode in _EMERGENCY:
                return "Powering on failed: emergency stop is active"
            if self.robot_mode < RobotMode.IDLE:
                self.robot_mode = RobotMode.IDLE
            return "Powering on"

    def brake_release(self) -> str:
        with self._lock:
            if self.robot_mode >= RobotMode.IDLE:
                self.robot_mode = RobotMode.RUNNING
            return "Brake releasing"

    def unlock_protective_stop(self) -> str:
        with self._lock:
            if self.safety_mode != SafetyMode.PROTECTIVE_STOP:
                return "Protective stop releasing"
            if time.monotonic() - self._stopped_at < self.unlock_delay:
                return (
                    f"Cannot unlock protective stop until {self.unlock_delay:g}s after "
                    "occurrence. Always inspect cause of protective stop before unlocking"
                )
            # The simulated arm's own stop (a collision) goes with it: this delay is the rule.
            self.cell.robot.unlock_protective_stop(delay=0.0)
            self.safety_mode = SafetyMode.NORMAL
            self.popup = ""
            self._publish()
            return "Protective stop releasing"

    def _halt(self, reason: str) -> None:
        self._end_program_locked(reason)
        if self.freedrive_on:
            self.set_freedrive(False)
        self.cell.robot.stop(10.0)

    @staticmethod
    def known_output(name: str) -> bool:
        return name in OUTPUT_TYPES or output_type(name) != "NOT_FOUND"
