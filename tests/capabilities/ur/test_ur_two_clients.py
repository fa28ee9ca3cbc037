"""Two clients on one UR controller, and a script end that comes with a protective stop.

The emulator runs in its own process; the clients are the unmodified ur_rtde. A UR runs one
program: a second client that uploads its control script ends the first one's, which the
first session names ("another program took the robot") instead of a script that stopped.
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.cells import open_cell
from capabilities.faults import PROTECTIVE_STOP, hold_check
from capabilities.ur.cell import RESTART_SCRIPT
from capabilities.ur.connection import NO_SCRIPT, TAKEN_OVER
from engine.build import build_tree
from engine.executor import Executor
from engine.hold import Hold
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import JointConfig, ParamType
from tests.capabilities.ur.emulators import HOME, wait_for

pytestmark = pytest.mark.sim


def test_a_second_client_takes_the_robot_and_the_first_session_says_so(
    tmp_path: Path, start_emulator, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, "capabilities.ur")
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    with open_cell(str(cell_file)) as first:
        assert wait_for(lambda: first.hold_reason() == "", 20)  # type: ignore[attr-defined]
        with open_cell(str(cell_file)) as second:
            assert wait_for(lambda: second.hold_reason() == "", 20)  # type: ignore[attr-defined]
            assert "a program already runs on the controller" in caplog.text  # the second's
            assert wait_for(lambda: first.hold_reason() == TAKEN_OVER, 20)  # type: ignore[attr-defined]
            assert TAKEN_OVER.startswith("another program took the robot: ")
            status = first.status()  # type: ignore[attr-defined]
            assert status.problem == TAKEN_OVER and status.clear_action == RESTART_SCRIPT
            state = emulator.state()
            assert state["script_clients"] == 2 and state["takeovers"] == 1
            assert any("took the robot" in m for m in state["messages"])
            assert second.hold_reason() == ""  # type: ignore[attr-defined]
            # Nothing is uploaded again on its own; the operator's clear takes it back.
            first.clear()  # type: ignore[attr-defined]
            assert wait_for(lambda: first.hold_reason() == "", 20)  # type: ignore[attr-defined]
            assert wait_for(lambda: second.hold_reason() == TAKEN_OVER, 20)  # type: ignore[attr-defined]


def test_a_script_end_just_before_the_protective_stop_is_held_as_the_stop_only(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    turn = NodeSpec(NodeKind.OPERATION, "turn", "turn", op="motion.move_joints", params={
        "target": Binding.fixed(JointConfig((HOME[0] + 1.2, *HOME[1:])), ParamType.JOINTS),
        "speed": Binding.fixed(0.3, ParamType.NUMBER),
    })  # fmt: skip
    reasons: list[str] = []
    lock = threading.Lock()
    with open_cell(str(cell_file)) as cell:
        check = hold_check(cell)
        assert check is not None

        def recording() -> Hold | None:
            hold = check()
            with lock:
                reason = hold.reason if hold is not None else ""
                if not reasons or reasons[-1] != reason:
                    reasons.append(reason)
            return hold

        tree = build_tree(PlanSpec(turn), CapabilityRegistry(cell=cell), clock=cell.clock)
        executor = Executor(tree, 20.0, [], hold=recording)
        executor.start()
        assert wait_for(lambda: emulator.state()["moving"], 20)
        # The program's end arrives 0.15 s before the safety mode, as a UR's streams can.
        emulator.protective_stop(lag=0.15)
        assert wait_for(lambda: PROTECTIVE_STOP in reasons, 10), reasons
        executor.stop()
    with lock:
        before = reasons[: reasons.index(PROTECTIVE_STOP)]
    assert NO_SCRIPT not in before, reasons
