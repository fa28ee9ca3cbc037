"""confirm, button_pressed and wait_for_button through the engine, with the console answered
or pressed from another thread (the GUI's, a pedal's).
"""

from __future__ import annotations

import threading
from typing import Any

from capabilities.base import CapabilityRegistry
from capabilities.cells import ManagedCell, open_cell
from capabilities.collaboration import OperatorConsole, capability
from capabilities.collaboration.console import ConsoleEvent, ConsoleEventKind
from engine.build import build_tree
from engine.events import Event, StatusChanged
from engine.executor import Executor, run_to_end
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.tree import BehaviorTree
from engine.types import ObjectModel, ParamType, Region

DEADLINE = 30.0  # generous wall-clock bound of a run; never the measured outcome


class ClockCell(ManagedCell):
    """The none cell with a clock the test sets."""

    def __init__(self) -> None:
        super().__init__()
        self.now = 0.0

    def clock(self) -> float:
        return self.now


def node(op: str, **params: Any) -> NodeSpec:
    bindings = {}
    for port, value in params.items():
        kind = {str: ParamType.TEXT, bool: ParamType.BOOL, float: ParamType.DURATION}[type(value)]
        bindings[port] = Binding.fixed(value, kind)
    return NodeSpec(NodeKind.OPERATION, name=op.split(".")[1], op=op, params=bindings)


def build(cell: Any, root: NodeSpec) -> BehaviorTree:
    registry = CapabilityRegistry([capability()], cell=cell)
    return build_tree(PlanSpec(root, "test"), registry, clock=cell.clock)


def on_prompt(console: OperatorConsole, react: Any) -> None:
    """Call ``react(prompt)`` on a new thread whenever a prompt is shown."""

    def heard(event: ConsoleEvent) -> None:
        if event.kind is ConsoleEventKind.PROMPT_SHOWN:
            threading.Thread(target=react, args=(event.prompt,)).start()

    console.add_listener(heard)


def test_the_none_cell_offers_the_operator_console() -> None:
    with open_cell("none") as cell:
        registry = CapabilityRegistry([capability()], cell=cell)
        assert isinstance(cell.interfaces()["operator"], OperatorConsole)
        assert registry.availability("collaboration.confirm").available


def test_confirm_succeeds_when_the_operator_says_yes() -> None:
    cell = ClockCell()
    on_prompt(cell.operator, lambda p: cell.operator.answer(p.id, True))
    tree = build(cell, node("collaboration.confirm", prompt="Is the bin empty?"))
    result = run_to_end(tree, 50.0, DEADLINE)
    assert result.status is Status.SUCCESS
    assert cell.operator.pending() == []


def test_confirm_fails_declined_when_the_operator_says_no() -> None:
    cell = ClockCell()
    on_prompt(cell.operator, lambda p: cell.operator.answer(p.id, False))
    tree = build(cell, node("collaboration.confirm", prompt="Go on?"))
    result = run_to_end(tree, 50.0, DEADLINE)
    assert result.status is Status.FAILURE
    assert tree.root.message == "declined"


def test_confirm_times_out_on_the_cells_clock_and_withdraws_the_prompt() -> None:
    cell = ClockCell()
    shown: list[Any] = []

    def expire(prompt: Any) -> None:
        shown.append(prompt)
        cell.now = 5.0  # the cell's clock passes the 2 s timeout

    on_prompt(cell.operator, expire)
    tree = build(cell, node("collaboration.confirm", prompt="Go on?", timeout=2.0))
    result = run_to_end(tree, 50.0, DEADLINE)
    assert result.status is Status.FAILURE
    assert tree.root.message == "timed out"
    assert cell.operator.pending() == [] and shown[0].reason == "timed out"


def test_stopping_the_run_withdraws_the_prompt() -> None:
    cell = ClockCell()
    shown = threading.Event()
    cell.operator.add_listener(
        lambda e: shown.set() if e.kind is ConsoleEventKind.PROMPT_SHOWN else None
    )
    tree = build(cell, node("collaboration.confirm", prompt="Go on?"))
    executor = Executor(tree, 50.0)
    executor.start()
    assert shown.wait(DEADLINE)
    prompt = cell.operator.pending()[0]
    executor.stop()
    assert executor.wait(DEADLINE) is not None
    assert cell.operator.pending() == []
    assert prompt.reason == "halted" and prompt.answer is None


def test_button_pressed_is_true_once_per_press() -> None:
    cell = ClockCell()
    cell.operator.press("continue")
    tree = build(cell, node("collaboration.button_pressed"))
    assert run_to_end(build(cell, node("collaboration.button_pressed")), 50.0, DEADLINE).status is (
        Status.SUCCESS
    )
    assert run_to_end(tree, 50.0, DEADLINE).status is Status.FAILURE  # consumed


def test_button_pressed_reads_the_named_button() -> None:
    cell = ClockCell()
    cell.operator.press("stop")
    tree = build(cell, node("collaboration.button_pressed", button="stop"))
    assert run_to_end(tree, 50.0, DEADLINE).status is Status.SUCCESS


def _run_pressing_when_running(cell: ClockCell, root: NodeSpec, press: str) -> Any:
    """Run ``root``; press ``press`` from another thread once the leaf is RUNNING."""
    pressed: list[bool] = []

    def listen(event: Event) -> None:
        if isinstance(event, StatusChanged) and event.new is Status.RUNNING and not pressed:
            pressed.append(True)
            threading.Thread(target=cell.operator.press, args=(press,)).start()

    tree = build(cell, root)
    return tree, run_to_end(tree, 50.0, DEADLINE, [listen])


def test_wait_for_button_succeeds_on_a_press_from_another_thread() -> None:
    cell = ClockCell()
    _, result = _run_pressing_when_running(cell, node("collaboration.wait_for_button"), "continue")
    assert result.status is Status.SUCCESS
    assert not cell.operator.consume("continue")  # the press was used up


def test_wait_for_button_ignores_other_buttons_and_times_out() -> None:
    cell = ClockCell()
    heard = threading.Event()

    def pressed_other(event: ConsoleEvent) -> None:
        if event.button == "stop":
            cell.now = 10.0  # after the wrong button, time runs out
            heard.set()

    cell.operator.add_listener(pressed_other)
    root = node("collaboration.wait_for_button", timeout=3.0)
    tree, result = _run_pressing_when_running(cell, root, "stop")
    assert heard.is_set()
    assert result.status is Status.FAILURE
    assert "timed out" in tree.root.message


def test_a_press_before_the_wait_started_counts_only_when_asked() -> None:
    cell = ClockCell()
    cell.operator.press("continue")
    counted = node("collaboration.wait_for_button", earlier_press_counts=True)
    assert run_to_end(build(cell, counted), 50.0, DEADLINE).status is Status.SUCCESS

    cell.operator.press("continue")
    cell.now = 0.0
    fresh = node("collaboration.wait_for_button", timeout=1.0)
    tree = build(cell, fresh)
    executor = Executor(tree, 50.0)
    executor.start()
    cell.now = 2.0  # no new press: the old one was forgotten, the wait times out
    result = executor.wait(DEADLINE)
    assert result is not None and result.status is Status.FAILURE


def test_confirm_without_text_fails_with_a_reason() -> None:
    cell = ClockCell()
    tree = build(cell, node("collaboration.confirm", prompt=" "))
    assert run_to_end(tree, 50.0, DEADLINE).status is Status.FAILURE
    assert "question" in tree.root.message


def test_handoff_operations_fail_with_the_reason_on_a_cell_without_cameras() -> None:
    cell = ClockCell()
    root = NodeSpec(
        NodeKind.OPERATION, name="handoff", op="collaboration.wait_for_handoff",
        params={
            "object": Binding.fixed(ObjectModel("kit_bin"), ParamType.OBJECT),
            "region": Binding.fixed(Region((0.5, 0.2, 0.0), 0.1), ParamType.REGION),
        },
    )  # fmt: skip
    tree = build(cell, root)
    assert run_to_end(tree, 50.0, DEADLINE).status is Status.FAILURE
    assert "has no shoulder camera" in tree.root.message
