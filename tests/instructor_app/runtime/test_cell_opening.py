"""The window opens cells in the background: it stays responsive while a real cell connects,
says what it waits for, refuses a second choice and a run meanwhile, and keeps the cell that
was open when the new one fails (a UR cell file whose host does not answer, through ur_rtde).
"""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QTimer

from capabilities.cells import open_cell
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window

DEAD_HOST = "127.254.0.1"  # loopback, nothing listening (test emulators: 127.20-219.x.y)


class TickWaitingOpener:
    """The real opener, called only after the GUI thread's timer ticked a few more times:
    when the opening ran on the GUI thread, those ticks could never come.
    """

    def __init__(self, ticks: list[int]) -> None:
        self.ticks = ticks
        self.names: list[str] = []
        self.ticks_seen: list[int] = []
        self.threads: list[str] = []

    def __call__(self, name: str, **kwargs: Any) -> Any:
        self.names.append(name)
        self.threads.append(threading.current_thread().name)
        if name != "none":
            start, deadline = self.ticks[0], time.monotonic() + 5.0
            while self.ticks[0] < start + 3 and time.monotonic() < deadline:
                time.sleep(0.005)
            self.ticks_seen.append(self.ticks[0] - start)
        return open_cell(name, **kwargs)


def test_a_dead_robot_host_leaves_the_window_responsive_and_the_old_cell_in_use(
    qtbot: Any, tmp_path: Path
) -> None:
    cell_file = tmp_path / "dead.cell.json"
    robot = {"kind": "ur", "host": DEAD_HOST, "model": "UR5e"}
    cell_file.write_text(json.dumps({"format_version": 2, "robot": robot}), "utf-8")
    ticks = [0]
    timer = QTimer()
    timer.setInterval(2)
    timer.timeout.connect(lambda: ticks.__setitem__(0, ticks[0] + 1))
    timer.start()
    opener = TickWaitingOpener(ticks)
    session = CellSession("none", opener=opener)
    session.open()
    before = session.cell
    dialogs = ScriptedDialogs()
    dialogs.cell_paths.append(str(cell_file))
    window = make_window(qtbot, session, tmp_path, dialogs)
    combo, run = window.cell_combo, window.run_actions.run
    refused: list[Any] = []
    window.controller.run_refused.connect(refused.extend)
    try:
        with qtbot.waitSignal(session.cell_ready, timeout=15_000) as ready:
            combo.activated.emit(combo.count() - 1)  # "Open cell file…"
            assert window.statusBar().currentMessage() == f"Connecting to {DEAD_HOST}…"
            assert not combo.isEnabled() and not run.isEnabled()
            assert combo.currentText() == "dead.cell.json"
            window.switch_cell("sim")  # a second choice meanwhile is refused, in words
            assert "still opening" in window.statusBar().currentMessage()
            assert not window.controller.run() and "still opening" in refused[0].message
        assert ready.args == [False]
        assert opener.ticks_seen[0] >= 3 and opener.threads[-1].startswith("costar-cell")
        assert "sim" not in opener.names
        ((title, message),) = dialogs.errors
        assert title == "Cell" and f"cannot connect to the UR controller at {DEAD_HOST}" in message
        assert session.cell is before and session.name == "none" and combo.currentText() == "none"
        assert "still using the none cell" in window.statusBar().currentMessage()
        assert combo.isEnabled() and run.isEnabled()
    finally:
        timer.stop()
        window.shutdown()
        session.close()


@pytest.mark.sim
def test_the_simulated_cell_opens_in_the_background_from_the_chooser(
    qtbot: Any, tmp_path: Path, none_session: CellSession
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    combo = window.cell_combo

    def move_joints_available() -> bool:
        items = window.views.palette.items()
        return next(i for i in items if i.op == "motion.move_joints").available

    on_gui_thread: list[bool] = []
    none_session.registry_changed.connect(
        lambda _r: on_gui_thread.append(threading.current_thread() is threading.main_thread())
    )
    assert not move_joints_available()  # no arm on the "none" cell
    with qtbot.waitSignal(none_session.cell_ready, timeout=30_000) as ready:
        combo.activated.emit(combo.findData("sim"))
        assert window.statusBar().currentMessage() == "Starting the simulated cell…"
        assert none_session.name == "none" and none_session.opening == "sim"
    assert ready.args == [True] and none_session.name == "sim" and on_gui_thread == [True]
    assert move_joints_available(), "the palette rebuilt from the simulated cell's registry"
    assert window.statusBar().currentMessage() == "Cell in use: sim"
    window.shutdown()
