"""OperatorPanel: questions from the plan appear with Yes/No; a click answers them; the
Continue button presses the console's button; events from other threads arrive safely.
"""

from __future__ import annotations

import threading
from typing import Any

from PySide6.QtCore import QCoreApplication, QEvent, Qt
from pytestqt.qtbot import QtBot

from capabilities.base import CapabilityRegistry
from capabilities.cells import ManagedCell
from capabilities.collaboration import OperatorConsole, capability
from engine.build import build_tree
from engine.executor import Executor
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType
from instructor_app.panels.operator import OperatorPanel

DEADLINE_MS = 20000


def make_panel(qtbot: QtBot, console: OperatorConsole | None) -> OperatorPanel:
    panel = OperatorPanel()
    qtbot.addWidget(panel)
    panel.set_console(console)
    panel.show()
    return panel


def test_clicking_yes_makes_the_running_confirm_succeed(qtbot: QtBot) -> None:
    cell = ManagedCell()
    panel = make_panel(qtbot, cell.operator)
    root = NodeSpec(NodeKind.OPERATION, name="ask", op="collaboration.confirm",
                    params={"prompt": Binding.fixed("Is the bin in place?", ParamType.TEXT)})  # fmt: skip
    registry = CapabilityRegistry([capability()], cell=cell)
    tree = build_tree(PlanSpec(root, "confirm"), registry, clock=cell.clock)
    executor = Executor(tree, 50.0)
    with qtbot.waitSignal(panel.prompt_shown, timeout=DEADLINE_MS) as shown:
        executor.start()  # the engine thread asks; the panel hears it in the GUI thread
    assert shown.args == ["Is the bin in place?"]
    row = panel.rows()[0]
    assert row.text_label.text() == "Is the bin in place?"
    qtbot.mouseClick(row.yes_button, Qt.MouseButton.LeftButton)
    result = executor.wait(DEADLINE_MS / 1000)
    assert result is not None and result.status is Status.SUCCESS
    qtbot.waitUntil(lambda: panel.rows() == [], timeout=DEADLINE_MS)
    assert "No questions" in panel.status_label.text()


def test_clicking_no_declines(qtbot: QtBot) -> None:
    console = OperatorConsole()
    panel = make_panel(qtbot, console)
    prompt = console.ask("Start the welder?")
    qtbot.waitUntil(lambda: len(panel.rows()) == 1, timeout=DEADLINE_MS)
    qtbot.mouseClick(panel.rows()[0].no_button, Qt.MouseButton.LeftButton)
    assert prompt.answer is False
    qtbot.waitUntil(lambda: panel.rows() == [], timeout=DEADLINE_MS)


def test_a_withdrawn_question_disappears(qtbot: QtBot) -> None:
    console = OperatorConsole()
    panel = make_panel(qtbot, console)
    prompt = console.ask("Go on?")
    qtbot.waitUntil(lambda: len(panel.rows()) == 1, timeout=DEADLINE_MS)
    with qtbot.waitSignal(panel.prompts_changed, timeout=DEADLINE_MS):
        console.cancel(prompt.id, "halted")
    assert panel.rows() == []


def test_questions_asked_from_other_threads_all_show_oldest_first(qtbot: QtBot) -> None:
    console = OperatorConsole()
    panel = make_panel(qtbot, console)
    threads = [threading.Thread(target=console.ask, args=(f"Q{i}",)) for i in range(5)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    qtbot.waitUntil(lambda: len(panel.rows()) == 5, timeout=DEADLINE_MS)
    ids = [row.prompt_id for row in panel.rows()]
    assert ids == [p.id for p in console.pending()]
    panel.layout().activate()
    tops = [row.geometry().top() for row in panel.rows()]
    assert tops == sorted(tops)  # on screen in the order of asking, top down
    assert "5 questions" in panel.status_label.text()


def test_the_continue_button_presses_the_consoles_button(qtbot: QtBot) -> None:
    console = OperatorConsole()
    panel = make_panel(qtbot, console)
    with qtbot.waitSignal(panel.button_pressed, timeout=DEADLINE_MS) as pressed:
        qtbot.mouseClick(panel.continue_button, Qt.MouseButton.LeftButton)
    assert pressed.args == ["continue"]
    assert console.consume("continue")


def test_questions_open_before_the_console_was_set_are_shown(qtbot: QtBot) -> None:
    console = OperatorConsole()
    console.ask("Already waiting?")
    panel = make_panel(qtbot, console)
    assert [row.text_label.text() for row in panel.rows()] == ["Already waiting?"]


def test_without_a_console_the_panel_is_disabled_and_switching_forgets_the_old_one(
    qtbot: QtBot,
) -> None:
    old = OperatorConsole()
    panel = make_panel(qtbot, old)
    old.ask("From the old cell?")
    qtbot.waitUntil(lambda: len(panel.rows()) == 1, timeout=DEADLINE_MS)
    panel.set_console(None)
    assert panel.rows() == [] and not panel.continue_button.isEnabled()
    assert "no operator console" in panel.status_label.text()
    seen: list[Any] = []
    panel.prompt_shown.connect(seen.append)
    old.ask("Still listening?")
    QCoreApplication.processEvents()  # a queued event, had one been posted, arrives here
    assert panel.rows() == [] and seen == []


def test_a_destroyed_panel_is_no_longer_told(qtbot: QtBot, caplog: Any) -> None:
    console = OperatorConsole()
    panel = OperatorPanel()
    panel.set_console(console)
    panel.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    console.ask("Anyone there?")
    assert not [r for r in caplog.records if "raised" in r.getMessage()]
