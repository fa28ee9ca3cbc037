"""A UR protective stop thrown into a Catch, and cleared by the plan through ur_rtde's dashboard.

The emulator runs in its own process; the client is the unmodified ur_rtde. The emulator
refuses to unlock earlier than its unlock delay after the stop, as PolyScope does, so the
clear operation has to wait for it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.cells import open_cell
from capabilities.faults import PROTECTIVE_STOP, hold_check
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.events import Event, RunHeld, StatusChanged
from engine.executor import Executor
from engine.library import SHIPPED_LIBRARY, load_subtree
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, SUCCESS
from engine.types import JointConfig, ParamType
from tests.capabilities.ur.emulators import FAST, HOME, wait_for

pytestmark = pytest.mark.sim

CLEAR_STOP = SHIPPED_LIBRARY / "recovery" / "ClearStopAndBackOff.subtree.json"


def _turn() -> NodeSpec:
    target = JointConfig((HOME[0] + 1.2, *HOME[1:]))
    return NodeSpec(NodeKind.OPERATION, "turn", "turn", op="motion.move_joints", params={
        "target": Binding.fixed(target, ParamType.JOINTS),
        "speed": Binding.fixed(0.3, ParamType.NUMBER),
    })  # fmt: skip


def _failures(events: list[Event], node_id: str) -> list[tuple[str, str]]:
    return [
        (e.error, e.message)
        for e in events
        if isinstance(e, StatusChanged) and e.node_id == node_id and e.new is FAILURE
    ]


def _where(executor: Executor) -> tuple[str, list[tuple[str, str, str]]]:
    """Why the run is held, and every node's status and message."""
    nodes = [(n.name, n.status.value, n.message) for n in executor.tree.iterate()]
    return executor.held, nodes


def test_a_protective_stop_is_thrown_into_the_catch_and_cleared_by_the_plan(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file, unlock_delay=1.0)
    subtree = load_subtree(CLEAR_STOP)
    handler = NodeSpec(NodeKind.SUBTREE, "recover", "recover", subtree=subtree.ref)
    catch = NodeSpec(NodeKind.CATCH, "catch", "catch", children=[_turn(), handler], params={
        "errors": Binding.fixed("protective_stop", ParamType.TEXT),
    })  # fmt: skip
    plan = PlanSpec(catch, "turn, caught", subtrees=[subtree])
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        tree = build_tree(plan, CapabilityRegistry(cell=cell), clock=cell.clock)
        executor = Executor(tree, 20.0, [events.append], hold=hold_check(cell))
        executor.start()
        assert wait_for(lambda: emulator.state()["moving"], 20)
        emulator.protective_stop()
        result = executor.wait(90)
        assert result is not None and result.status is SUCCESS, result
        assert cell.hold_reason() == ""  # type: ignore[attr-defined]
    (error, message), *_ = _failures(events, "turn")
    assert error == ErrorType.PROTECTIVE_STOP.value and PROTECTIVE_STOP in message
    assert not [e for e in events if isinstance(e, RunHeld)]  # thrown, never held
    # The plan waited for the emulator's delay, unlocked it, and went back to the safe pose.
    assert emulator.state()["safety_mode"] == 1  # NORMAL
    assert emulator.state()["q"] == pytest.approx(list(HOME), abs=0.01)


def test_clearing_fails_with_emergency_stop_which_a_plan_may_not_clear(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    clear = NodeSpec(NodeKind.OPERATION, "clear", "clear", op="motion.clear_protective_stop")
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        emulator.emergency_stop()
        assert wait_for(lambda: cell.hold_reason() == "emergency stop")  # type: ignore[attr-defined]
        tree = build_tree(PlanSpec(clear), CapabilityRegistry(cell=cell), clock=cell.clock)
        executor = Executor(tree, 20.0, [events.append])  # no hold: the operation decides
        executor.start()
        result = executor.wait(30)
        assert result is not None and result.status is FAILURE
    (error, message), *_ = _failures(events, "clear")
    assert error == ErrorType.EMERGENCY_STOP.value, message
    assert "for the operator to clear" in message


def test_a_collision_of_the_emulated_arm_is_the_controllers_protective_stop(
    tmp_path: Path, start_emulator
) -> None:
    from capabilities.sim.testing import down_at

    cell_file = tmp_path / "emulated.cell.json"
    # Nothing here is paced by the wall clock (the moves only have to end, the collision is
    # the simulated arm's force in simulated time): the cell runs faster than real time.
    emulator = start_emulator("5.12", speed=FAST, write_cell=cell_file)
    subtree = load_subtree(CLEAR_STOP)
    body = NodeSpec(NodeKind.SEQUENCE, "pick", "pick", children=[
        NodeSpec(NodeKind.OPERATION, "above", "above", op="motion.move_to", params={
            "target": Binding.fixed(down_at(0.5, 0.0, 0.15), ParamType.POSE)}),
        NodeSpec(NodeKind.OPERATION, "down", "down", op="motion.move_to", params={
            "target": Binding.fixed(down_at(0.5, 0.0, -0.05), ParamType.POSE),
            "mode": Binding.fixed("linear", ParamType.TEXT),
            "speed": Binding.fixed(0.4, ParamType.NUMBER)}),
    ])  # fmt: skip
    handler = NodeSpec(NodeKind.SUBTREE, "recover", "recover", subtree=subtree.ref)
    catch = NodeSpec(NodeKind.CATCH, "catch", "catch", children=[body, handler], params={
        "errors": Binding.fixed("protective_stop", ParamType.TEXT),
    })  # fmt: skip
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        plan = PlanSpec(catch, "into the table", subtrees=[subtree])
        tree = build_tree(plan, CapabilityRegistry(cell=cell), clock=cell.clock)
        executor = Executor(tree, 20.0, [events.append], hold=hold_check(cell))
        executor.start()
        result = executor.wait(90)
        # What held it or where it stands, should it not end (it once ran out the 90 s).
        assert result is not None and result.status is SUCCESS, (result, *_where(executor))
    (error, message), *_ = _failures(events, "down")
    assert error == ErrorType.PROTECTIVE_STOP.value and PROTECTIVE_STOP in message, message
    assert any("on the table" in m for m in emulator.state()["messages"])  # the arm's cause
    assert emulator.state()["q"] == pytest.approx(list(HOME), abs=0.01)
