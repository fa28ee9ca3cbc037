"""The emulated control program: what ur_rtde's control script does, read from the registers.

The emulator never interprets URScript. When ur_rtde uploads its control script, the emulator
runs this instead: every controller cycle it reads the command in ``input_int_register_0`` (plus
the register offset the script declares), executes it on the simulated arm, and answers in the
output registers the way the script does: 1 in ``output_int_register_0`` when ready for a
command, 2 when done with it, and the asynchronous progress word in ``output_int_register_2``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from capabilities.ur.frames import matrix_from_rotvec_pose

if TYPE_CHECKING:
    from capabilities.robot.commands import CommandHandle
    from capabilities.ur_emulator.controller import EmulatedController

__all__ = ["ControlProgram"]

_log = logging.getLogger(__name__)

READY, DONE = 1, 2
NO_CMD, MOVEJ, MOVEJ_IK, MOVEL, MOVEL_FK = 0, 1, 2, 3, 4
SET_PAYLOAD, TEACH_MODE, END_TEACH_MODE = 17, 18, 19
SET_TCP, PROTECTIVE_STOP, STOPL, STOPJ, SET_WATCHDOG = 29, 31, 33, 34, 35
GET_TCP_OFFSET, IS_STEADY = 40, 47
FREEDRIVE_MODE, END_FREEDRIVE_MODE, GET_FREEDRIVE_STATUS = 52, 53, 54
WATCHDOG, STOP_SCRIPT = 99, 255
FREEDRIVE_SINCE = (5, 10)
# How many cycles in a row must see a silence past the watchdog's period before it trips (see
# _watchdog_expired): 10 ms at 500 Hz when the emulator is not held up itself.
_CONFIRM_CYCLES = 5
_HELD_UP_S = 0.05  # a cycle this late means the emulator itself was held up


class ControlProgram:
    """One run of the control script on the emulated controller (controller thread only)."""

    def __init__(self, ctl: EmulatedController, reg_offset: int) -> None:
        self._ctl = ctl
        self._off = reg_offset
        self._executing = False
        self._move: CommandHandle | None = None
        self._sync: CommandHandle | None = None  # a blocking command still running
        self._stop: CommandHandle | None = None  # an asynchronous stop under way
        self._op_id = 0
        self._writes = 0
        self._watchdog: float | None = None  # s without an update of the command register
        self._watchdog_since = 0.0
        self._silent_cycles = 0  # cycles in a row that saw a silence past the period
        self._last_check = 0.0  # when the watchdog was last checked (a cycle's time)
        self._handlers: dict[int, Callable[[], None]] = {
            MOVEJ: lambda: self._move_joints(self._floats(0, 6)),
            MOVEJ_IK: self._move_joints_ik,
            MOVEL: lambda: self._move_linear(self._floats(0, 6)),
            MOVEL_FK: self._move_linear_fk,
            STOPJ: self._stop_move,
            STOPL: self._stop_move,
            TEACH_MODE: lambda: ctl.set_freedrive(True),
            END_TEACH_MODE: lambda: ctl.set_freedrive(False),
            FREEDRIVE_MODE: lambda: self._since(FREEDRIVE_SINCE, lambda: ctl.set_freedrive(True)),
            END_FREEDRIVE_MODE: lambda: self._since(
                FREEDRIVE_SINCE, lambda: ctl.set_freedrive(False)
            ),
            GET_FREEDRIVE_STATUS: lambda: self._since(
                FREEDRIVE_SINCE, lambda: self._write_int(1, int(ctl.freedrive_on))
            ),
            SET_TCP: lambda: ctl.set_tcp(self._floats(0, 6)),
            GET_TCP_OFFSET: lambda: self._write_floats(0, ctl.tcp_rotvec()),
            IS_STEADY: lambda: self._write_int(1, int(not ctl.arm_moving())),
            SET_PAYLOAD: lambda: None,
            SET_WATCHDOG: self._set_watchdog,
            WATCHDOG: lambda: None,  # ur_rtde's kick writes NO_CMD: this never arrives
            PROTECTIVE_STOP: lambda: ctl.protective_stop("triggered by the control script"),
        }
        self._progress(-1)
        self._write_int(0, READY)

    # ---------------------------------------------------------------- registers

    def _int(self, index: int) -> int:
        return int(self._ctl.input_value(f"input_int_register_{index + self._off}", 0))

    def _floats(self, start: int, count: int) -> list[float]:
        return [
            float(self._ctl.input_value(f"input_double_register_{start + i + self._off}", 0.0))
            for i in range(count)
        ]

    def _write_int(self, index: int, value: int) -> None:
        self._ctl.set_output_int(index + self._off, value)

    def _write_floats(self, start: int, values: list[float]) -> None:
        for i, value in enumerate(values):
            self._ctl.set_output_double(start + i + self._off, value)

    def _progress(self, value: int) -> None:
        """The script's asynchronous progress word: op id, change count, running bit."""
        self._writes = (self._writes + 1) % 128
        if value == 0:
            self._op_id = (self._op_id + 1) % 128
        word = self._writes * 65536 + self._op_id * 16777216
        if value >= 0:
            word += (value & 0x7FFF) + 32768
        self._write_int(2, word)

    # ---------------------------------------------------------------- the main loop

    def step(self) -> bool:
        """One controller cycle; False when the program ended (stop script, watchdog)."""
        if self._watchdog_expired():
            return False
        self._poll_motion()
        if self._sync is not None:
            return True
        cmd = self._int(0)
        if cmd == NO_CMD:
            self._executing = False
            self._write_int(0, READY)
            return True
        if self._executing:
            return True
        self._executing = True
        if cmd == STOP_SCRIPT:
            return False
        handler = self._handlers.get(cmd)
        if handler is None:
            self._ctl.text(f"command {cmd} is not emulated: the control script stops")
            return False
        handler()
        if self._sync is None:
            self._write_int(0, DONE)
        return True

    def _set_watchdog(self) -> None:
        """rtde_set_watchdog(register, frequency, "stop") on the command register."""
        frequency = self._floats(0, 1)[0]
        self._watchdog = 1.0 / frequency if frequency > 0 else None
        self._watchdog_since = self._last_check = time.monotonic()

    def _watchdog_expired(self) -> bool:
        """True when the watched register was not written for a watchdog period: the
        program stops, as rtde_set_watchdog's "stop" does (the arm halts with it).
        """
        if self._watchdog is None:
            return False
        register = f"input_int_register_{self._off}"
        now = time.monotonic()
        if now - self._last_check > _HELD_UP_S:
            # This emulator was held up itself (a camera frame rendered while it holds the
            # interpreter, a loaded machine): what the client sent meanwhile waits unread or
            # unapplied, so the client's period starts again now.
            self._watchdog_since = now
        self._last_check = now
        silence = self._ctl.input_silence(register, self._watchdog_since)
        if silence <= self._watchdog or self._ctl.inputs_pending():
            self._silent_cycles = 0
            return False
        # The emulator's own delay is not the client's silence: a package its server thread
        # took from the socket waits for this cycle's lock, or for the interpreter while a
        # camera frame is rendered (pybullet holds it ~0.2 s). It trips once the silence has
        # lasted over cycles that let that thread apply what it holds (each cycle ends by
        # letting go of the lock and the interpreter).
        self._silent_cycles += 1
        if self._silent_cycles < _CONFIRM_CYCLES:
            return False
        self._ctl.text(f"RTDE watchdog: {register} not updated for {silence:.2f} s")
        return True

    def end(self) -> None:
        """The program is killed: moves in flight stop where they are (no register writes)."""
        for handle in (self._move, self._sync):
            if handle is not None:
                handle.cancel()
        self._move = self._sync = None

    def _poll_motion(self) -> None:
        if self._move is not None and self._move.done():
            self._move = None
            self._progress(-1)
        if self._stop is not None and self._stop.done():
            self._stop = None
            self._progress(-1)
        if self._sync is not None and self._sync.done():
            self._sync = None
            self._write_int(0, DONE)

    # ---------------------------------------------------------------- commands

    def _since(self, version: tuple[int, int], action: Callable[[], None]) -> None:
        # The script's lines marked $5.10 are removed on older controllers: a no-op there.
        if self._ctl.version[:2] >= version:
            action()

    def _start(self, handle: CommandHandle | None) -> None:
        self._stop_async_move()
        if handle is None:
            return
        if self._int(1) == 1:
            self._move = handle
            self._progress(0)
        else:
            self._sync = handle

    def _stop_async_move(self) -> None:
        if self._move is not None:
            self._move.cancel()
            self._move = None
            self._progress(-1)

    def _move_joints(self, q: list[float]) -> None:
        values = self._floats(6, 2)
        self._start(self._ctl.move_joints(q, values[0], values[1]))

    def _move_joints_ik(self) -> None:
        q = self._ctl.inverse_kinematics(matrix_from_rotvec_pose(self._floats(0, 6)))
        if q is None:
            self._ctl.text("movej_ik: no inverse kinematics solution: the control script stops")
            self._ctl.end_program()
            return
        self._move_joints(list(q))

    def _move_linear(self, pose: list[float]) -> None:
        values = self._floats(6, 2)
        self._start(self._ctl.move_linear(matrix_from_rotvec_pose(pose), values[0], values[1]))

    def _move_linear_fk(self) -> None:
        tcp = self._ctl.forward_kinematics(self._floats(0, 6))
        values = self._floats(6, 2)
        self._start(self._ctl.move_linear(np.asarray(tcp), values[0], values[1]))

    def _stop_move(self) -> None:
        decel = self._floats(0, 1)[0]
        asynchronous = self._int(1) == 1
        self._stop_async_move()
        handle = self._ctl.stop_arm(decel if decel > 0 else 2.0)
        if asynchronous:
            self._stop = handle
            self._progress(0)
        else:
            self._sync = handle
