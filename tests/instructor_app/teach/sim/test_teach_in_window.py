"""Teaching by hand in the Instructor on the simulated cell, through its widgets: waypoints
taught by freedrive and by jogging are used by a plan that then runs; a waypoint taught
relative to the cup follows the cup after it was moved (through detection at run time);
Move here stops when its button is let go.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from engine.status import Status
from engine.types import Waypoint
from instructor_app.main_window import MainWindow
from instructor_app.panels.move import FREEDRIVE_TOGGLE_ON
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import (
    ScriptedDialogs,
    choose,
    make_window,
    run_to_end,
    search_insert,
    select,
    set_value,
)
from tests.instructor_app.teach.held import hold_ready

LEFT = Qt.MouseButton.LeftButton


@pytest.fixture
def window(qtbot: Any, fast_sim: CellSession, tmp_path: Path) -> MainWindow:
    shown = make_window(qtbot, fast_sim, tmp_path)
    shown.new_plan()
    return shown


def arm_of(session: CellSession) -> Any:
    return session.cell.interfaces()["arm"]


def record(qtbot: Any, window: MainWindow, name: str, frame: str, reference: str = "") -> Waypoint:
    panel = window.views.waypoints
    choose(qtbot, panel.frame_combo, frame)
    panel.object_field.setText(reference)
    qtbot.keyClicks(panel.name_field, name)
    qtbot.mouseClick(panel.record_button, LEFT)
    return next(w for w in window.document.plan.waypoints if w.name == name)


def click_and_wait(qtbot: Any, window: MainWindow, button: Any) -> None:
    """Click a jog button and wait until its jog ended. Only a jog's end counts: the end of
    what ran before (freedrive off) may still be on its way from the worker on a loaded
    machine, and taken for the jog's, the test went on while the jog had not moved yet.
    """
    with qtbot.waitSignal(
        window.views.teacher.finished,
        timeout=30_000,
        check_params_cb=lambda what, _problem: what.startswith("jog"),
    ) as blocker:
        qtbot.mouseClick(button, LEFT)
    assert blocker.args[1] == "", blocker.args


def plan_of_moves(qtbot: Any, window: MainWindow, targets: list[Waypoint]) -> list[str]:
    """Sequence[move_to target] built with the palette and the inspector; the node ids."""
    search_insert(qtbot, window, "sequence", "sequence")
    ids = []
    for target in targets:
        node_id = search_insert(qtbot, window, "motion.move_to", "motion.move_to")
        set_value(qtbot, window, node_id, "target", target)
        ids.append(node_id)
    return ids


def test_waypoints_taught_by_freedrive_and_by_jogging_run_in_a_plan(
    qtbot: Any, window: MainWindow, fast_sim: CellSession
) -> None:
    arm, move = arm_of(fast_sim), window.views.move
    start = arm.tcp_pose().position
    # On the simulated cell Freedrive is a toggle: a click turns it on, push the tool by hand.
    qtbot.mouseClick(move.freedrive_button, LEFT)
    qtbot.waitUntil(arm.freedrive_active, timeout=5_000)
    qtbot.waitUntil(lambda: move.freedrive_button.text() == FREEDRIVE_TOGGLE_ON)
    arm.apply_tcp_wrench((0.0, 30.0, -15.0), duration=0.5)
    qtbot.waitUntil(lambda: math.dist(arm.tcp_pose().position, start) > 0.03, timeout=10_000)
    qtbot.mouseClick(move.freedrive_button, LEFT)  # the next click turns it off
    qtbot.waitUntil(lambda: not arm.freedrive_active(), timeout=5_000)
    qtbot.waitUntil(lambda: not arm.is_moving(), timeout=10_000)
    by_hand = record(qtbot, window, "by hand", "world")
    assert by_hand.pose is not None and math.dist(by_hand.pose.position, start) > 0.03

    choose(qtbot, move.step_combo, "50 mm / 15°")
    click_and_wait(qtbot, window, move.jog_buttons["z+"])
    click_and_wait(qtbot, window, move.jog_buttons["x-"])
    jogged = record(qtbot, window, "jogged", "joints")
    assert jogged.joints is not None
    assert arm.tcp_pose().position == pytest.approx(
        (
            by_hand.pose.position[0] - 0.05,
            by_hand.pose.position[1],
            by_hand.pose.position[2] + 0.05,
        ),
        abs=1e-3,
    )

    nodes = plan_of_moves(qtbot, window, [by_hand, jogged])
    jog_while: list[bool] = []  # the robot is the plan's while it runs
    window.controller.run_state_changed.connect(
        lambda _state: jog_while.append(move.jog_buttons["x+"].isEnabled())
    )
    outcome = run_to_end(qtbot, window, 60_000)
    assert outcome.status is Status.SUCCESS, outcome
    assert jog_while[0] is False and move.jog_buttons["x+"].isEnabled()
    assert arm.joint_positions() == pytest.approx(jogged.joints.positions, abs=2e-3)

    # The pose node's own Move here (inspector), held until the arm is there.
    select(window, nodes[0])
    move_here = window.views.inspector.teach_buttons["target"].move_button
    assert move_here.isEnabled()
    hold_ready(qtbot, move_here)
    with qtbot.waitSignal(window.views.teacher.finished, timeout=60_000) as blocker:
        qtbot.mousePress(move_here, LEFT)
    qtbot.mouseRelease(move_here, LEFT)
    assert blocker.args == ["move here", ""]
    assert arm.tcp_pose().position == pytest.approx(by_hand.pose.position, abs=1e-3)


def _push_cup(client: int, cell: Any, dx: float, dy: float) -> None:
    import pybullet  # the test moves the cup as a hand would

    body = cell.scene.body_id("cup")
    pos, orn = pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
    pybullet.resetBasePositionAndOrientation(
        body, (pos[0] + dx, pos[1] + dy, pos[2]), orn, physicsClientId=client
    )


def detect(qtbot: Any, window: MainWindow) -> str:
    """Run a plan that takes the arm out of the camera's view (to where it is now) and
    looks (the shoulder camera's markers); the look node's id.
    """
    search_insert(qtbot, window, "sequence", "sequence")
    out_of_view = record(qtbot, window, "out of view", "joints")
    node_id = search_insert(qtbot, window, "motion.move_to", "motion.move_to")
    set_value(qtbot, window, node_id, "target", out_of_view)
    node_id = search_insert(qtbot, window, "markers.detect_markers", "markers.detect_markers")
    set_value(qtbot, window, node_id, "camera", "shoulder")
    assert run_to_end(qtbot, window).status is Status.SUCCESS
    return node_id


def test_a_waypoint_relative_to_the_cup_follows_the_cup(
    qtbot: Any, window: MainWindow, fast_sim: CellSession
) -> None:
    arm, cell = arm_of(fast_sim), fast_sim.cell
    look = detect(qtbot, window)
    cup = window.views.teacher.interface("world").best("cup").pose  # what the camera saw
    # Teach: bring the tool above the cup by jogging, then Record relative to it.
    move = window.views.move
    choose(qtbot, move.step_combo, "50 mm / 15°")
    click_and_wait(qtbot, window, move.jog_buttons["z-"])
    smart = record(qtbot, window, "near cup", "object", "cup")
    assert smart.reference == "cup" and smart.pose is not None
    taught_at = arm.tcp_pose()

    cell.sim.call(lambda client: _push_cup(client, cell, 0.06, -0.04))
    cell.sim.wait_sim(0.5)
    truth = cell.truth_pose("cup")  # ground truth: only the test reads it
    select(window, look)  # the plan steps out of view, looks again, then goes
    node_id = search_insert(qtbot, window, "motion.move_to", "motion.move_to")
    set_value(qtbot, window, node_id, "target", smart)
    outcome = run_to_end(qtbot, window, 60_000)
    assert outcome.status is Status.SUCCESS, window.failure_button.toolTip()
    reached = arm.tcp_pose()
    # The tool keeps its place relative to the cup (the cup's symmetry may turn it about the
    # cup's axis: distance from the axis and height above the cup are what must hold).
    for pose in (taught_at, reached):
        assert pose is not None
    rel_then = cup.inverse().compose(taught_at).position
    rel_now = truth.inverse().compose(reached).position
    assert math.hypot(*rel_now[:2]) == pytest.approx(math.hypot(*rel_then[:2]), abs=0.01)
    assert rel_now[2] == pytest.approx(rel_then[2], abs=0.01)
    shift = [a - b for a, b in zip(reached.position, taught_at.position, strict=True)]
    assert shift[:2] == pytest.approx([0.06, -0.04], abs=0.015)


def test_move_here_stops_when_the_button_is_let_go(
    qtbot: Any, window: MainWindow, fast_sim: CellSession
) -> None:
    arm, panel = arm_of(fast_sim), window.views.waypoints
    far = record(qtbot, window, "start", "joints")
    window.views.move.speed_slider.setValue(100)
    choose(qtbot, window.views.move.step_combo, "50 mm / 15°")
    for _ in range(3):
        click_and_wait(qtbot, window, window.views.move.joint_buttons[(0, 1)])  # base +45 deg
    q_before = arm.joint_positions()
    panel.select("start")
    assert panel.move_button.isEnabled()
    hold_ready(qtbot, panel.move_button)
    qtbot.mousePress(panel.move_button, LEFT)
    qtbot.waitUntil(lambda: q_before[0] - arm.joint_positions()[0] > 0.05, timeout=20_000)
    assert arm.is_moving()
    with qtbot.waitSignal(window.views.teacher.finished, timeout=20_000) as blocker:
        qtbot.mouseRelease(panel.move_button, LEFT)
    assert blocker.args == ["move to start", ""]
    qtbot.waitUntil(lambda: not arm.is_moving(), timeout=5_000)
    stopped = arm.joint_positions()
    fast_sim.cell.sim.wait_sim(0.5)
    assert arm.joint_positions() == pytest.approx(stopped, abs=1e-4)  # it stays
    assert stopped[0] - far.joints.positions[0] > 0.2  # far from the waypoint: it stopped
    # Held to the end, it arrives.
    hold_ready(qtbot, panel.move_button)
    with qtbot.waitSignal(window.views.teacher.finished, timeout=60_000) as blocker:
        qtbot.mousePress(panel.move_button, LEFT)
    assert blocker.args == ["move to start", ""]
    qtbot.mouseRelease(panel.move_button, LEFT)
    assert arm.joint_positions() == pytest.approx(far.joints.positions, abs=2e-3)


def test_teach_in_the_inspector_asks_before_a_shared_waypoint_and_says_what_changed(
    qtbot: Any, window: MainWindow, fast_sim: CellSession
) -> None:
    """Issue 26: Teach overwrote the shared 'observe' waypoint with no sign."""
    observe = record(qtbot, window, "observe", "world")
    nodes = plan_of_moves(qtbot, window, [observe, observe])
    move = window.views.move
    choose(qtbot, move.step_combo, "50 mm / 15°")
    click_and_wait(qtbot, window, move.jog_buttons["z+"])
    select(window, nodes[0])
    dialogs = window.dialogs
    assert isinstance(dialogs, ScriptedDialogs)
    dialogs.overwrite_answers = [True]
    qtbot.mouseClick(window.views.inspector.teach_buttons["target"].teach_button, LEFT)
    assert dialogs.asked[-1][0] == "overwrite" and "observe" in dialogs.asked[-1][1]
    said = window.statusBar().currentMessage()
    assert said.startswith("Taught the waypoint 'observe': (") and "→" in said
    assert "Undo" in said
    taught = window.document.plan.waypoints[0]
    assert taught.pose is not None and observe.pose is not None
    assert taught.pose.position[2] == pytest.approx(observe.pose.position[2] + 0.05, abs=1e-3)
    window.actions_by_name["undo"].trigger()
    assert window.document.plan.waypoints[0] == observe
    assert window.document.node(nodes[1]).params["target"].value == observe
