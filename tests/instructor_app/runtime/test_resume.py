"""Resume from this node: after a run stopped or failed, the operator runs on from a node."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtGui import QAction

from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window
from tests.instructor_app.runtime.plans import number, op, text

RESUME = "Resume from this node"


def _plan() -> PlanSpec:
    """Set X, then a step that fails (the operator fixes it by hand), then check X."""
    steps = [
        NodeSpec(
            NodeKind.OPERATION,
            name="remember",
            op="debug.set_param",
            params={"value": number(5), "name": Binding.reference("X")},
        ),
        op("debug.fail", "stuck part", message=text("the part jammed")),
        op("debug.check_param", "check", value=Binding.reference("X"), expected=number(5)),
    ]
    return PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=steps), name="jam")


def _menu_action(window: Any, node_id: str) -> QAction | None:
    canvas = window.views.canvas
    menu = canvas.commands.context_menu(node_id, canvas)
    return next((a for a in menu.actions() if a.text() == RESUME), None)


def test_resume_from_a_node_runs_on_from_it_with_what_the_run_found(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(_plan()), None)
    ids = {n.name: n.id for _, n in window.document.plan.walk()}
    assert _menu_action(window, ids["check"]) is None  # no run yet: nothing to resume
    controller = window.controller
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as first:
        controller.run()
    assert first.args[0].status is Status.FAILURE
    action = _menu_action(window, ids["check"])
    assert action is not None
    with qtbot.waitSignal(controller.run_finished, timeout=10000) as resumed:
        action.trigger()
    outcome = resumed.args[0]
    assert outcome.status is Status.SUCCESS
    # The nodes before it are done (the failed one was fixed by hand), not run again; the
    # check reads X, which the first run wrote.
    assert outcome.statuses[ids["remember"]] is Status.SUCCESS
    assert outcome.statuses[ids["stuck part"]] is Status.SUCCESS
    assert outcome.statuses[ids["check"]] is Status.SUCCESS
    assert window.views.canvas.status_of(ids["stuck part"]) is Status.SUCCESS
    lines = window.views.log.lines()
    assert any("resumed from check (2 nodes before it counted as done)" in t for t in lines)
