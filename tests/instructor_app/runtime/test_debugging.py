"""Breakpoints, stepping, skip and force in the Instructor, through its keys, menus and canvas."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMenu

from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, ParameterDecl, PlanSpec
from engine.status import Status
from engine.types import ParamType, Pose
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import click_node, make_window
from tests.instructor_app.runtime.plans import number, op, text

GOAL = Pose((0.4, 0.1, 0.3), (1.0, 0.0, 0.0, 0.0))


def _move_plan() -> PlanSpec:
    """first, a pretend move to GOAL (a few ticks), last."""
    move = op("debug.pretend_move", "move to GOAL", target=Binding.reference("GOAL"))
    move.params["ticks"] = number(3)
    steps = [op("debug.succeed", "first"), move, op("debug.succeed", "last")]
    return PlanSpec(
        tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=steps),
        name="move",
        parameters=[ParameterDecl("GOAL", ParamType.POSE, GOAL)],
    )


def _grasp_plan() -> PlanSpec:
    """A grasp inside a Catch of grasp_failed whose handler is the recovery."""
    grasp = op("debug.succeed", "grasp CUP")
    recover = op("debug.log", "recover", message=text("opening the gripper"))
    catch = NodeSpec(
        NodeKind.CATCH,
        name="catch a failed grasp",
        params={"errors": text("grasp_failed")},
        children=[grasp, recover],
    )
    return PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=[catch]), name="grasp")


def _ids(window: Any) -> dict[str, str]:
    return {n.name: n.id for _, n in window.document.plan.walk()}


def _menu_entry(window: Any, node_id: str, *path: str) -> QAction:
    canvas = window.views.canvas
    menu: QMenu = canvas.commands.context_menu(node_id, canvas)
    for text_ in path[:-1]:
        action = next(a for a in menu.actions() if a.text() == text_)
        sub = action.menu()
        assert isinstance(sub, QMenu)
        menu = sub
    return next(a for a in menu.actions() if a.text() == path[-1])


def _debug_menu(window: Any) -> dict[str, QAction]:
    bar = window.menuBar()
    debug = next(a for a in bar.actions() if a.text() == "&Debug").menu()
    return {a.text(): a for a in debug.actions() if a.text()}


def test_a_breakpoint_pauses_before_the_move_and_the_run_continues(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_move_plan()), None)
    ids = _ids(window)
    canvas, controller = window.views.canvas, window.controller
    window.activateWindow()  # the shortcuts are the window's
    qtbot.waitUntil(window.isActiveWindow)
    click_node(qtbot, window, ids["move to GOAL"])
    qtbot.keyClick(window.views.canvas.viewer, Qt.Key.Key_F9)
    assert controller.debugging.breakpoints == {ids["move to GOAL"]}
    assert canvas.debug_marks(ids["move to GOAL"]) == (True, "", False)  # the red dot
    with qtbot.waitSignal(controller.run_paused, timeout=10000) as paused:
        qtbot.keyClick(window.views.canvas.viewer, Qt.Key.Key_F5)
    assert paused.args[0] == ids["move to GOAL"]
    qtbot.waitUntil(lambda: canvas.debug_marks(ids["move to GOAL"])[2])  # marked as paused at
    message = window.statusBar().currentMessage()
    assert message.startswith("Paused at move to GOAL: breakpoint before move to GOAL"), message
    assert canvas.status_of(ids["first"]) is Status.SUCCESS
    assert canvas.status_of(ids["move to GOAL"]) is Status.IDLE  # not started
    if os.environ.get("COSTAR_SHOT"):  # a picture of the window at the breakpoint
        window.grab().save(os.environ["COSTAR_SHOT"])
    actions = _debug_menu(window)
    assert set(actions) >= {"&Step", "Step &Over", "Run to Selected &Node", "&Continue"}
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as finished:
        actions["&Continue"].trigger()
    assert finished.args[0].status is Status.SUCCESS
    assert canvas.debug_marks(ids["move to GOAL"]) == (True, "", False)  # the dot stays
    saved = dump_plan(window.document.plan)
    assert "breakpoint" not in saved  # not in the plan file
    window.document.load_text(saved, None)  # the plan opened again: kept in the settings
    assert canvas.debug_marks(ids["move to GOAL"]) == (True, "", False)
    window.document.load_text(dump_plan(_move_plan()), None)  # another plan: none
    assert window.controller.debugging.breakpoints == frozenset()


def test_step_over_and_run_to_a_node(qtbot: Any, none_session: CellSession, tmp_path: Path) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_move_plan()), None)
    ids = _ids(window)
    controller = window.controller
    click_node(qtbot, window, ids["move to GOAL"])
    actions = _debug_menu(window)
    with qtbot.waitSignal(controller.run_paused, timeout=10000) as paused:
        actions["Run to Selected &Node"].trigger()  # starts the run, paused there
    assert paused.args == [ids["move to GOAL"], "ran to move to GOAL"]
    with qtbot.waitSignal(controller.run_paused, timeout=10000) as paused:
        actions["Step &Over"].trigger()
    assert paused.args == [ids["move to GOAL"], "step: move to GOAL is SUCCESS"]
    assert window.views.canvas.status_of(ids["last"]) is Status.IDLE
    with qtbot.waitSignal(controller.run_finished, timeout=10000):
        actions["&Continue"].trigger()


def test_a_forced_grasp_failure_runs_the_recovery_of_its_catch(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_grasp_plan()), None)
    ids = _ids(window)
    canvas, controller = window.views.canvas, window.controller
    _menu_entry(window, ids["grasp CUP"], "Force Result", "Fail: grasp_failed").trigger()
    assert canvas.debug_marks(ids["grasp CUP"]) == (False, "forced: grasp_failed", False)
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as finished:
        controller.run()
    outcome = finished.args[0]
    assert outcome.status is Status.SUCCESS  # the Catch's handler recovered
    assert outcome.statuses[ids["grasp CUP"]] is Status.FAILURE
    assert outcome.statuses[ids["recover"]] is Status.SUCCESS
    assert canvas.debug_marks(ids["grasp CUP"]) == (False, "", False)  # given once
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as again:
        controller.run()
    assert again.args[0].statuses[ids["grasp CUP"]] is Status.SUCCESS


def test_a_skipped_node_reports_skipped(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_move_plan()), None)
    ids = _ids(window)
    _menu_entry(window, ids["move to GOAL"], "Skip This Node").trigger()
    assert window.views.canvas.debug_marks(ids["move to GOAL"])[1] == "skipped"
    with qtbot.waitSignal(window.controller.run_finished, timeout=10000) as finished:
        window.controller.run()
    assert finished.args[0].status is Status.SUCCESS
    assert finished.args[0].statuses[ids["move to GOAL"]] is Status.SKIPPED
    _menu_entry(window, ids["move to GOAL"], "Do Not Skip This Node").trigger()
    assert window.views.canvas.debug_marks(ids["move to GOAL"])[1] == ""


def _counting_plan() -> PlanSpec:
    """COUNT := 0, then three times: COUNT += 1 and a step."""
    step = NodeSpec(
        NodeKind.SEQUENCE,
        name="one round",
        children=[
            NodeSpec(NodeKind.SCRIPT, name="count", params={"code": text("COUNT += 1")}),
            op("debug.succeed", "step"),
        ],
    )
    repeat = NodeSpec(NodeKind.REPEAT, name="three rounds", params={"count": number(3)})
    repeat.children = [step]
    start = NodeSpec(NodeKind.SCRIPT, name="start", params={"code": text("COUNT := 0")})
    return PlanSpec(
        tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=[start, repeat]), name="count"
    )


def test_a_breakpoint_after_a_node_on_a_condition_set_from_its_menu(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_counting_plan()), None)
    ids = _ids(window)
    canvas, controller = window.views.canvas, window.controller
    window._dialogs.text_answers = ["COUNT >="]  # a script that does not parse: refused
    _menu_entry(window, ids["step"], "Breakpoint", "Only When…").trigger()
    assert controller.debugging.breakpoint(ids["step"]) is None
    assert "condition not set" in window.statusBar().currentMessage()
    window._dialogs.text_answers = ["COUNT >= 2"]
    _menu_entry(window, ids["step"], "Breakpoint", "Only When…").trigger()
    _menu_entry(window, ids["step"], "Breakpoint", "After").trigger()
    assert canvas.debug_marks(ids["step"]) == (True, "break after if COUNT >= 2", False)
    with qtbot.waitSignal(controller.run_paused, timeout=10000) as paused:
        controller.run()
    assert paused.args[0] == ids["step"] and "after step" in paused.args[1]
    board = window.views.blackboard
    qtbot.waitUntil(lambda: board.values().get("COUNT") == 2)  # not at the first round
    with qtbot.waitSignal(controller.run_paused, timeout=10000):
        controller.resume()
    qtbot.waitUntil(lambda: board.values().get("COUNT") == 3)
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as finished:
        controller.resume()
    assert finished.args[0].status is Status.SUCCESS
    window.document.load_text(dump_plan(window.document.plan), None)  # opened again: kept
    kept = controller.debugging.breakpoint(ids["step"])
    assert kept is not None and (kept.before, kept.after, kept.condition) == (
        False,
        True,
        "COUNT >= 2",
    )
