"""OperatorConsole: latched buttons, prompts answered or withdrawn, listeners, threads;
digital inputs as buttons.
"""

from __future__ import annotations

import threading

import pytest

from capabilities.collaboration.console import (
    ConsoleEvent,
    ConsoleEventKind,
    OperatorConsole,
    PromptState,
)
from capabilities.collaboration.inputs import DigitalInputButton, SimDigitalInput


def test_a_press_latches_until_consumed_once() -> None:
    console = OperatorConsole()
    assert not console.consume("continue")
    console.press("continue")
    console.press("continue")  # a double press is one press for the plan
    assert console.consume("continue")
    assert not console.consume("continue")
    assert console.presses("continue") == 2


def test_buttons_are_independent_and_clear_forgets_a_press() -> None:
    console = OperatorConsole()
    console.press("continue")
    console.press("stop")
    console.clear("continue")
    assert not console.consume("continue")
    assert console.consume("stop")


def _in_threads(fn: object, count: int) -> None:
    barrier = threading.Barrier(count)

    def run() -> None:
        barrier.wait()
        fn()  # type: ignore[operator]  # the callers pass functions

    threads = [threading.Thread(target=run) for _ in range(count)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()


def test_presses_from_many_threads_are_all_counted() -> None:
    console = OperatorConsole()
    _in_threads(lambda: console.press("continue"), 16)
    assert console.presses("continue") == 16
    assert console.consume("continue")
    assert not console.consume("continue")


def test_one_press_is_consumed_by_exactly_one_of_many_threads() -> None:
    console = OperatorConsole()
    console.press("continue")
    got: list[bool] = []
    _in_threads(lambda: got.append(console.consume("continue")), 16)
    assert sorted(got) == [False] * 15 + [True]


def test_a_prompt_is_pending_until_answered_and_answered_once() -> None:
    console = OperatorConsole()
    prompt = console.ask("Is the fixture clamped?", "check clamp")
    assert [p.id for p in console.pending()] == [prompt.id]
    assert prompt.state is PromptState.PENDING and prompt.answer is None
    assert console.answer(prompt.id, True)
    assert not console.answer(prompt.id, False)  # the first answer stands
    assert prompt.answer is True and prompt.closed
    assert console.pending() == []
    assert prompt.wait(0)


def test_a_cancelled_prompt_has_no_answer_and_says_why() -> None:
    console = OperatorConsole()
    prompt = console.ask("Go on?")
    assert console.cancel(prompt.id, "timed out")
    assert prompt.state is PromptState.CANCELLED
    assert prompt.answer is None and prompt.reason == "timed out"
    assert not console.answer(prompt.id, True)
    assert not console.cancel("p999")


def test_prompt_ids_are_unique_and_pending_is_oldest_first() -> None:
    console = OperatorConsole()
    first, second = console.ask("one"), console.ask("two")
    assert first.id != second.id
    assert [p.text for p in console.pending()] == ["one", "two"]
    assert console.prompt(second.id) is second


def test_done_callbacks_run_on_close_or_at_once_when_closed() -> None:
    console = OperatorConsole()
    prompt = console.ask("Go on?")
    seen: list[PromptState] = []
    prompt.add_done_callback(lambda p: seen.append(p.state))
    console.answer(prompt.id, False)
    prompt.add_done_callback(lambda p: seen.append(p.state))
    assert seen == [PromptState.NO, PromptState.NO]


def test_listeners_hear_prompts_and_buttons_and_can_be_removed() -> None:
    console = OperatorConsole()
    heard: list[ConsoleEvent] = []
    console.add_listener(heard.append)
    prompt = console.ask("Go on?")
    console.answer(prompt.id, True)
    console.press("continue")
    kinds = [e.kind for e in heard]
    assert kinds == [
        ConsoleEventKind.PROMPT_SHOWN,
        ConsoleEventKind.PROMPT_CLOSED,
        ConsoleEventKind.BUTTON_PRESSED,
    ]
    assert heard[0].prompt is prompt and heard[2].button == "continue"
    console.remove_listener(heard.append)
    console.press("continue")
    assert len(heard) == 3


def test_a_failing_listener_does_not_break_the_console() -> None:
    console = OperatorConsole()
    heard: list[ConsoleEvent] = []

    def broken(event: ConsoleEvent) -> None:
        raise RuntimeError("listener bug")

    console.add_listener(broken)
    console.add_listener(heard.append)
    console.press("continue")
    assert len(heard) == 1 and console.consume("continue")


def test_a_prompt_answered_from_another_thread_wakes_the_waiter() -> None:
    console = OperatorConsole()
    prompt = console.ask("Go on?")
    answerer = threading.Thread(target=lambda: console.answer(prompt.id, True))
    answerer.start()
    assert prompt.wait(10.0)  # a generous deadline, not the outcome
    answerer.join()
    assert prompt.answer is True


def test_listeners_are_told_on_the_thread_that_made_the_change() -> None:
    console = OperatorConsole()
    threads: list[str] = []
    console.add_listener(lambda event: threads.append(threading.current_thread().name))
    presser = threading.Thread(target=console.press, name="pedal-thread")
    presser.start()
    presser.join()
    assert threads == ["pedal-thread"]


def test_a_rising_edge_of_a_digital_input_presses_the_button_once() -> None:
    console = OperatorConsole()
    pedal = SimDigitalInput()
    button = DigitalInputButton(pedal, console, "continue")
    assert not button.poll_once()
    pedal.set(True)
    assert button.poll_once()
    assert not button.poll_once()  # held down: still one press
    pedal.set(False)
    button.poll_once()
    assert console.presses("continue") == 1


def test_the_digital_input_poller_thread_presses_the_button() -> None:
    console = OperatorConsole()
    pedal = SimDigitalInput()
    pressed = threading.Event()
    console.add_listener(lambda event: pressed.set())
    button = DigitalInputButton(pedal, console, "continue", period=0.001)
    button.start()
    try:
        pedal.set(True)
        assert pressed.wait(10.0)
    finally:
        button.stop()
    assert console.consume("continue")


@pytest.mark.parametrize("text", ["", "   "])
def test_a_question_needs_text(text: str) -> None:
    from capabilities.collaboration.errors import CollaborationError

    with pytest.raises(CollaborationError):
        OperatorConsole().ask(text)
