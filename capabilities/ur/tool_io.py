"""Digital I/O of a UR cell: a suction cup switched by a digital output (SuctionBackend), and
digital inputs and the pendant's teach button read as operator buttons (a foot pedal).

Outputs are set through ur_rtde's RTDEIOInterface on the connection's I/O thread; what the
outputs and inputs are is read from the controller's state (``actual_digital_output_bits``:
bits 0-7 standard, 8-15 configurable, 16-17 tool; inputs likewise). The cup is mounted on the
flange here (no holster): ``in_hand`` is always True and the holster poses are refused.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from capabilities.robot.commands import CommandHandle
from capabilities.ur.connection import URConnection, fault_reason
from capabilities.ur.errors import URError, ur_words
from engine.types import Pose

__all__ = ["DigitalPin", "TeachButtonReleased", "URDigitalInput", "URSuctionCup"]

_BANK_SHIFT = {"standard": 0, "configurable": 8, "tool": 16}
_SETTERS = {
    "standard": "setStandardDigitalOut",
    "configurable": "setConfigurableDigitalOut",
    "tool": "setToolDigitalOut",
}


@dataclass(frozen=True)
class DigitalPin:
    """One digital pin: bank ("standard", "configurable" or "tool") and index in the bank."""

    bank: str
    index: int

    def __post_init__(self) -> None:
        limit = 2 if self.bank == "tool" else 8
        if self.bank not in _BANK_SHIFT or not 0 <= self.index < limit:
            raise ValueError(
                f"digital pin must be standard 0-7, configurable 0-7 or tool 0-1, "
                f"got {self.bank} {self.index}"
            )

    @property
    def bit(self) -> int:
        return 1 << (_BANK_SHIFT[self.bank] + self.index)


def set_output(connection: URConnection, pin: DigitalPin, on: bool) -> CommandHandle:
    """Switch a digital output; the handle finishes when the controller reports it switched."""
    handle = CommandHandle(f"set {pin.bank} digital output {pin.index}")

    def run() -> None:
        problem = fault_reason(connection.state)
        if problem.startswith("connection lost"):
            handle.resolve(False, f"{handle.name}: {problem}")
            return
        setter = _SETTERS[pin.bank]
        if not connection.with_io(lambda io: getattr(io, setter)(pin.index, on)):
            handle.resolve(False, f"{handle.name}: refused by the controller")
            return
        connection.add_monitor(lambda conn: _switched(conn, handle, pin, on))

    def failed(future: object) -> None:
        exc = getattr(future, "exception", lambda: None)()
        if exc is not None:
            handle.resolve(False, f"{handle.name}: connection lost ({ur_words(exc)})")

    connection.submit(run).add_done_callback(failed)
    return handle


def _switched(conn: URConnection, handle: CommandHandle, pin: DigitalPin, on: bool) -> bool:
    if not conn.state.connected:
        handle.resolve(False, f"{handle.name}: {fault_reason(conn.state)}")
        return True
    if bool(conn.state.digital_outputs & pin.bit) == on:
        handle.resolve(True)
        return True
    return handle.done()


class URSuctionCup:
    """A suction cup on the flange: vacuum on a digital output, part sensor on an input.

    Args:
        connection: the open UR connection.
        vacuum: the output that switches the vacuum.
        sensor: the input that reads "part held" (None: the vacuum state stands in for it).
    """

    def __init__(
        self, connection: URConnection, vacuum: DigitalPin, sensor: DigitalPin | None = None
    ) -> None:
        self._conn = connection
        self.vacuum = vacuum
        self.sensor = sensor

    def suction_on(self) -> CommandHandle:
        return set_output(self._conn, self.vacuum, True)

    def suction_off(self) -> CommandHandle:
        return set_output(self._conn, self.vacuum, False)

    def vacuum_on(self) -> bool:
        return bool(self._conn.state.digital_outputs & self.vacuum.bit)

    def has_part(self) -> bool:
        if self.sensor is None:
            return self.vacuum_on()
        return bool(self._conn.state.digital_inputs & self.sensor.bit)

    def in_hand(self) -> bool:
        return True

    def handle_grasp_pose(self) -> Pose:
        raise URError("this cell's suction cup is mounted on the flange: it has no holster")

    def holstered_tip_pose(self) -> Pose:
        raise URError("this cell's suction cup is mounted on the flange: it has no holster")


class URDigitalInput:
    """One digital input of the controller (a DigitalInputSource: a foot pedal).

    It reads the state snapshot the connection's I/O thread keeps: never a call into ur_rtde.
    """

    def __init__(self, connection: URConnection, pin: DigitalPin) -> None:
        self._conn = connection
        self.pin = pin

    def read(self) -> bool:
        return bool(self._conn.state.digital_inputs & self.pin.bit)


class TeachButtonReleased:
    """High while the pendant's teach button is not held: its rising edge is the release that
    ends a hand-guided move, when the operator wants the waypoint recorded.

    A monitor on the I/O thread latches every state that shows the button held, so a short
    press between two reads of the button's poller still reads low once.
    """

    def __init__(self, connection: URConnection) -> None:
        self._conn = connection
        self._held_seen = False
        connection.watch(self._watch)

    def _watch(self, conn: URConnection) -> bool:
        if conn.state.teach_button:
            self._held_seen = True
        return False  # for the connection's lifetime

    def read(self) -> bool:
        state = self._conn.state
        if state.teach_button:
            return False
        if self._held_seen:
            self._held_seen = False
            return False
        return state.connected


if TYPE_CHECKING:
    from capabilities.tool.backend import SuctionBackend

    def _conforms(cup: URSuctionCup) -> SuctionBackend:
        return cup
