"""The cell goes back to the scene's start: before each run when the plan asks for it
(checkbox of the Plan panel), and on the Reset cell action.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from engine.status import Status
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.capabilities.sim.test_cup_to_bin import cup_in_bin
from tests.instructor_app.conftest import EXAMPLES
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window


def _run(qtbot: Any, window: MainWindow) -> Status:
    with qtbot.waitSignal(window.controller.run_finished, timeout=180_000) as blocker:
        window.run_actions.run.trigger()
    return blocker.args[0].status


def test_two_runs_in_a_row_of_the_example_both_succeed(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    dialogs.open_paths = [str(EXAMPLES / "cup_to_bin.costar.json")]
    window = make_window(qtbot, fast_sim, tmp_path, dialogs)
    window.actions_by_name["open"].trigger()
    box = window.views.plan_settings.reset_box
    if not box.isChecked():  # the shipped example may already ask for it
        qtbot.mouseClick(box, Qt.MouseButton.LeftButton)
    assert window.document.plan.reset_cell
    assert _run(qtbot, window) is Status.SUCCESS
    fast_sim.cell.sim.wait_sim(1.0)
    assert cup_in_bin(fast_sim.cell.truth_pose("cup"), fast_sim.cell.truth_pose("waste_bin"))
    assert _run(qtbot, window) is Status.SUCCESS  # the cup was put back on the table first
    fast_sim.cell.sim.wait_sim(1.0)
    assert cup_in_bin(fast_sim.cell.truth_pose("cup"), fast_sim.cell.truth_pose("waste_bin"))


def test_reset_cell_action_puts_the_cup_back(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, fast_sim, tmp_path)
    start = fast_sim.cell.truth_pose("cup")
    home = fast_sim.cell.interfaces()["arm"].joint_positions()
    cell = fast_sim.cell
    cell.sim.call(lambda client: _push_cup(client, cell))
    cell.sim.wait_sim(0.5)
    assert cell.truth_pose("cup").position[0] > start.position[0] + 0.05
    window.actions_by_name["reset_cell"].trigger()
    assert fast_sim.cell is not cell  # a fresh cell, no state of the last one
    # where the seed placed it (the physics keeps stepping: settling moves it by microns)
    back = fast_sim.cell.truth_pose("cup").position
    assert max(abs(a - b) for a, b in zip(back, start.position, strict=True)) < 1e-3
    joints = fast_sim.cell.interfaces()["arm"].joint_positions()
    assert max(abs(a - b) for a, b in zip(joints, home, strict=True)) < 1e-3
    assert window.statusBar().currentMessage() == "The sim cell was reset"


def _push_cup(client: int, cell: Any) -> None:
    import pybullet  # the test pushes the cup as a hand would

    body = cell.scene.body_id("cup")
    pos, orn = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
    pybullet.resetBasePositionAndOrientation(
        body, (pos[0] + 0.1, pos[1], pos[2]), orn, physicsClientId=client
    )


def _names(session: CellSession) -> set[str]:
    return set(session.cell.scene.names())


def _settle(qtbot: Any, session: CellSession) -> None:
    """Wait until no cell is opening (a plan's scene opens in the background)."""
    qtbot.waitUntil(lambda: not session.opening, timeout=60_000)


def test_opening_a_plan_loads_its_scene_and_reset_cell_restores_that_one(
    qtbot: Any, fast_sim: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    dialogs.open_paths = [
        str(EXAMPLES / "kitting.costar.json"),
        str(EXAMPLES / "cup_to_bin.costar.json"),
    ]
    window = make_window(qtbot, fast_sim, tmp_path, dialogs)
    assert "cup" in _names(fast_sim)  # the cell's default scene
    window.actions_by_name["open"].trigger()  # the kitting example names kitting_handoff
    _settle(qtbot, fast_sim)
    assert "plate_3_holes" in _names(fast_sim) and "cup" not in _names(fast_sim)
    window.actions_by_name["reset_cell"].trigger()
    assert "plate_3_holes" in _names(fast_sim) and "cup" not in _names(fast_sim)
    window.actions_by_name["open"].trigger()  # cup to bin names none: the cell's default
    _settle(qtbot, fast_sim)
    assert {"cup", "waste_bin"} <= _names(fast_sim) and "plate_3_holes" not in _names(fast_sim)
    window.actions_by_name["reset_cell"].trigger()
    assert {"cup", "waste_bin"} <= _names(fast_sim) and "plate_3_holes" not in _names(fast_sim)
    window.switch_cell("none")
    _settle(qtbot, fast_sim)
    window.switch_cell("sim")
    _settle(qtbot, fast_sim)
    assert fast_sim.name == "sim" and "plate_3_holes" not in _names(fast_sim)
    assert {"cup", "waste_bin"} <= _names(fast_sim)
