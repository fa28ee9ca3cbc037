"""The emulated controller's faults as a UR has them: a blocked move is a protective stop with
its popup, which the pendant (the ``unlock`` control command) unlocks after the delay only.
"""

from __future__ import annotations

import pytest

from capabilities.robot.commands import CommandHandle
from capabilities.sim.cell import SimCell
from capabilities.ur.modes import SafetyMode
from capabilities.ur_emulator.controller import EmulatedController
from capabilities.ur_emulator.errors import EmulatorError
from tests.capabilities.ur.emulators import wait_for

pytestmark = pytest.mark.sim

BLOCKED = "blocked: the TCP stopped 12.0 mm and 0.10 deg from the target (a collision?)"


def test_a_blocked_move_is_a_protective_stop_with_the_controllers_popup() -> None:
    cell = SimCell(speed=None)
    cell.start()
    ctl = EmulatedController(cell, unlock_delay=0.0)
    try:
        ctl._watch(CommandHandle.failed("move_linear", BLOCKED))
        assert wait_for(lambda: ctl.safety_mode == SafetyMode.PROTECTIVE_STOP, 5)
        assert "position deviates from path" in ctl.popup and "a collision?" in ctl.popup
        assert any(m.startswith("Protective stop: position deviates") for m in ctl.messages)
        assert ctl.unlock_protective_stop() == "Protective stop releasing"
        assert ctl.safety_mode == SafetyMode.NORMAL and ctl.popup == ""
    finally:
        ctl.close()
        cell.close()


def test_the_pendant_unlocks_a_protective_stop_once_the_delay_has_passed(start_emulator) -> None:
    emulator = start_emulator("5.12", unlock_delay=1.0)
    emulator.protective_stop()
    with pytest.raises(EmulatorError, match="Cannot unlock protective stop until 1s"):
        emulator.unlock()
    assert emulator.state()["safety_mode"] == int(SafetyMode.PROTECTIVE_STOP)
    assert emulator.state()["popup"] == "Protective stop: injected"
    assert wait_for(lambda: _unlocked(emulator), 5)
    assert emulator.state()["safety_mode"] == int(SafetyMode.NORMAL)


def _unlocked(emulator) -> bool:  # type: ignore[no-untyped-def]
    try:
        emulator.unlock()
    except EmulatorError:
        return False
    return True
