"""The Instructor on the simulated cell after a collision: the failed node shows protective_stop,
the status bar shows the stop and offers its unlock once the delay has passed, and "Resume
from this node" runs on after the operator cleared it and took the obstacle away.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from capabilities.bullet import pybullet
from capabilities.faults import PROTECTIVE_STOP
from capabilities.robot.cell_file import CellConfig
from capabilities.robot.cell_robot import RobotSettings
from capabilities.sim.testing import add_box, down_at
from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType, Pose
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window
from tests.instructor_app.runtime.plans import op, text

pytestmark = pytest.mark.sim

RESUME = "Resume from this node"
WAIT_MS = 60_000


def _move(name: str, target: Pose, mode: str) -> NodeSpec:
    return op("motion.move_to", name, target=Binding.fixed(target, ParamType.POSE),
              mode=text(mode))  # fmt: skip


def _plan() -> PlanSpec:
    """Above the table, then down in a Catch of protective_stop whose handler calls the
    operator (it fails: the plan stops there).
    """
    down = _move("down", down_at(0.5, 0.0, 0.06), "linear")
    call = op("debug.fail", "call the operator", message=text("clear the cell, then resume"))
    catch = NodeSpec(NodeKind.CATCH, name="catch", children=[down, call], params={
        "errors": Binding.fixed("protective_stop", ParamType.TEXT),
    })  # fmt: skip
    top = NodeSpec(NodeKind.SEQUENCE, name="top", children=[
        _move("above", down_at(0.5, 0.0, 0.25), "joint"), catch,
    ])  # fmt: skip
    return PlanSpec(tree=top, name="blocked")


def _menu_action(window: Any, node_id: str) -> Any:
    canvas = window.views.canvas
    menu = canvas.commands.context_menu(node_id, canvas)
    return next((a for a in menu.actions() if a.text() == RESUME), None)


def test_resume_from_the_failed_move_after_the_operator_clears_the_stop(
    qtbot: Any, tmp_path: Path
) -> None:
    config = dataclasses.replace(CellConfig(), robot=RobotSettings(unlock_delay=0.5))
    cell_file = tmp_path / "quick.cell.json"
    cell_file.write_text(json.dumps(config.to_json()), encoding="utf-8")
    session = CellSession(str(cell_file))  # real time, as the Instructor runs it
    assert session.open()
    try:
        sim = session.cell.sim
        obstacle = add_box(sim, (0.2, 0.2, 0.08), (0.5, 0.0), mass=0.0)  # a fixture in the way
        window = make_window(qtbot, session, tmp_path)
        window.document.load_text(dump_plan(_plan()), None)
        ids = {n.name: n.id for _, n in window.document.plan.walk()}
        controller = window.controller
        with qtbot.waitSignal(controller.run_finished, timeout=WAIT_MS) as first:
            controller.run()
        assert first.args[0].status is Status.FAILURE
        assert first.args[0].statuses[ids["down"]] is Status.FAILURE
        lines = window.views.log.lines()
        assert any(f"down failed (protective_stop): {PROTECTIVE_STOP}" in t for t in lines), lines
        # The status bar shows the stop, and its unlock once the delay has passed.
        label, clear = window.robot_status, window.robot_clear
        qtbot.waitUntil(lambda: label.isVisibleTo(window) and label.fault == PROTECTIVE_STOP)
        qtbot.waitUntil(lambda: clear.isVisibleTo(window), timeout=WAIT_MS)
        assert clear.text() == "Unlock protective stop"
        sim.call(lambda client: pybullet.removeBody(obstacle, physicsClientId=client))
        qtbot.mouseClick(clear, Qt.MouseButton.LeftButton)
        qtbot.waitUntil(lambda: not label.isVisibleTo(window), timeout=WAIT_MS)
        assert not clear.isVisibleTo(window) and session.cell.hold_reason() == ""
        action = _menu_action(window, ids["down"])
        assert action is not None
        with qtbot.waitSignal(controller.run_finished, timeout=WAIT_MS) as resumed:
            action.trigger()
        outcome = resumed.args[0]
        assert outcome.status is Status.SUCCESS, outcome
        assert outcome.statuses[ids["above"]] is Status.SUCCESS  # counted as done
        assert outcome.statuses[ids["down"]] is Status.SUCCESS
        assert abs(sim.robot.tcp_pose().position[2] - 0.06) < 0.002  # it got there
    finally:
        session.close()
