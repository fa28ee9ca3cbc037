"""The Instructor on a UR cell (the loopback emulator through ur_rtde): the cell chooser opens a
cell file, and the toolbar shows connection, robot mode, safety mode and program state live.
"""

from __future__ import annotations

from pathlib import Path

import dashboard_client
import pytest
from PySide6.QtCore import Qt

from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window

pytestmark = pytest.mark.sim

WAIT_MS = 15_000


def test_the_toolbar_shows_each_robot_state(qtbot, tmp_path: Path, emulator) -> None:
    cell_file = str(tmp_path / "emulated.cell.json")
    session = CellSession("none")
    session.open()
    dialogs = ScriptedDialogs()
    dialogs.cell_paths.append(cell_file)
    window = make_window(qtbot, session, tmp_path, dialogs)
    label = window.robot_status
    assert not label.isVisibleTo(window)  # no robot controller on the "none" cell
    # The cell chooser's last entry asks for a cell file; it opens in the background.
    combo = window.cell_combo
    with qtbot.waitSignal(session.cell_ready, timeout=WAIT_MS) as ready:
        combo.activated.emit(combo.count() - 1)
        assert window.statusBar().currentMessage() == f"Connecting to {emulator.host}…"
        assert not combo.isEnabled() and not window.run_actions.run.isEnabled()
    assert ready.args == [True] and combo.isEnabled() and window.run_actions.run.isEnabled()
    assert session.name == cell_file and combo.currentText() == "emulated.cell.json"
    try:
        text = label.text
        qtbot.waitUntil(lambda: "RUNNING" in text() and "PLAYING" in text(), timeout=WAIT_MS)
        assert label.isVisibleTo(window) and "safety NORMAL" in text() and not label.fault

        emulator.protective_stop()
        qtbot.waitUntil(lambda: label.fault == "protective stop", timeout=WAIT_MS)
        assert "PROTECTIVE_STOP" in text() and "protective stop" in text()
        pendant = dashboard_client.DashboardClient(emulator.host)
        pendant.connect()
        pendant.unlockProtectiveStop()  # the operator clears it; the cell uploads the script
        qtbot.waitUntil(lambda: not label.fault and "PLAYING" in text(), timeout=WAIT_MS)

        emulator.emergency_stop()
        qtbot.waitUntil(lambda: label.fault == "emergency stop", timeout=WAIT_MS)
        emulator.release_emergency_stop()
        qtbot.waitUntil(lambda: "powered off" in label.fault, timeout=WAIT_MS)
        assert "POWER_OFF" in text()
        pendant.powerOn()
        pendant.brakeRelease()
        qtbot.waitUntil(lambda: not label.fault and "PLAYING" in text(), timeout=WAIT_MS)

        emulator.kill_script()  # stopped on the pendant: the operator restarts it here
        qtbot.waitUntil(lambda: "control script is not running" in label.fault, timeout=WAIT_MS)
        assert "program STOPPED" in text()
        restart = window.robot_clear
        assert restart.isVisibleTo(window) and restart.text() == "Restart control script"
        qtbot.mouseClick(restart, Qt.MouseButton.LeftButton)
        qtbot.waitUntil(lambda: not label.fault and "PLAYING" in text(), timeout=WAIT_MS)
        assert not restart.isVisibleTo(window)

        emulator.kill()
        qtbot.waitUntil(lambda: label.fault.startswith("connection lost"), timeout=WAIT_MS)
        assert text().startswith("Robot: connection lost")
    finally:
        session.close()


def test_a_protective_stop_during_a_run_is_said_in_words_and_the_run_goes_on(
    qtbot, tmp_path: Path, emulator
) -> None:
    from engine.files import save_plan
    from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
    from engine.status import Status
    from engine.types import JointConfig, ParamType
    from instructor_app.document.editing import PlanDocument
    from instructor_app.runtime.controller import RunController
    from tests.capabilities.ur.emulators import HOME, wait_for

    target = JointConfig((HOME[0] + 1.2, *HOME[1:]))
    move = NodeSpec(NodeKind.OPERATION, "turn", op="motion.move_joints", params={
        "target": Binding.fixed(target, ParamType.JOINTS),
        "speed": Binding.fixed(0.5, ParamType.NUMBER),
    })  # fmt: skip
    plan_path = tmp_path / "turn.costar.json"
    save_plan(PlanSpec(move, "turn"), plan_path)
    session = CellSession(str(tmp_path / "emulated.cell.json"))
    assert session.open()
    try:
        document = PlanDocument()
        document.open(plan_path)
        controller = RunController(document, session, rate_hz=20.0)
        logs: list[tuple[str, str]] = []
        controller.log_message.connect(lambda text, level: logs.append((text, level)))
        with qtbot.waitSignal(controller.run_finished, timeout=60_000) as finished:
            controller.run()
            assert wait_for(lambda: emulator.state()["moving"], 20)
            emulator.protective_stop()
            qtbot.waitUntil(
                lambda: any(t.startswith("The run is held: protective stop") for t, _ in logs),
                timeout=WAIT_MS,
            )
            pendant = dashboard_client.DashboardClient(emulator.host)
            pendant.connect()
            pendant.unlockProtectiveStop()
        assert finished.args[0].status is Status.SUCCESS
        assert ("The robot is ready again: the run goes on", "info") in logs
    finally:
        session.close()


def test_a_held_run_keeps_its_node_running_and_offers_the_unlock_counted_down(
    qtbot, tmp_path: Path, emulator, monkeypatch
) -> None:
    """A protective stop outside a Catch holds the run: the log and the status bar say so and
    how to clear it, the moving node stays RUNNING (amber) and held, and the status bar's
    Unlock is greyed with the seconds left until the controller allows it; pressing it then
    unlocks the stop and the run goes on to its end.
    """
    import capabilities.ur.cell as ur_cell
    from engine.files import dump_plan
    from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
    from engine.status import Status
    from engine.types import JointConfig, ParamType
    from tests.capabilities.ur.emulators import HOME, wait_for

    monkeypatch.setattr(ur_cell, "STOP_UNLOCK_DELAY", 2.0)  # a UR's is 5 s
    target = JointConfig((HOME[0] + 1.2, *HOME[1:]))
    move = NodeSpec(NodeKind.OPERATION, "turn", op="motion.move_joints", params={
        "target": Binding.fixed(target, ParamType.JOINTS),
        "speed": Binding.fixed(0.4, ParamType.NUMBER),
    })  # fmt: skip
    session = CellSession(str(tmp_path / "emulated.cell.json"))
    assert session.open()
    try:
        window = make_window(qtbot, session, tmp_path)
        window.document.load_text(dump_plan(PlanSpec(move, "turn")), None)
        turn = window.document.plan.tree.id
        controller, clear = window.controller, window.robot_clear
        held = "held: protective stop, clear it on the pendant or press Unlock protective stop"
        with qtbot.waitSignal(controller.run_finished, timeout=60_000) as finished:
            controller.run()
            assert wait_for(lambda: emulator.state()["moving"], 20)
            emulator.protective_stop()
            qtbot.waitUntil(lambda: controller.held == "protective stop", timeout=WAIT_MS)
            lines = window.views.log.lines()
            assert any(f"The run is {held}" in line for line in lines), lines
            assert held in window.statusBar().currentMessage()
            # The status label follows the cell's status on its own poll, not the hold signal.
            qtbot.waitUntil(
                lambda: held.removeprefix("held: ") in window.robot_status.text(), timeout=WAIT_MS
            )
            qtbot.wait(300)  # several drains while held: the node stays running
            assert controller.statuses[turn] is Status.RUNNING
            panel = window.running_panel
            assert panel.node_ids() == [turn] and held in panel.item(0).text()
            # The unlock is offered at once, greyed and counted down, then allowed.
            qtbot.waitUntil(lambda: clear.isVisibleTo(window), timeout=WAIT_MS)
            assert not clear.isEnabled() and clear.text().endswith(" s)"), clear.text()
            qtbot.waitUntil(clear.isEnabled, timeout=WAIT_MS)
            assert clear.text() == "Unlock protective stop"
            qtbot.mouseClick(clear, Qt.MouseButton.LeftButton)
        assert finished.args[0].status is Status.SUCCESS
        assert emulator.state()["safety_mode"] == 1  # NORMAL: unlocked through the dashboard
    finally:
        session.close()
