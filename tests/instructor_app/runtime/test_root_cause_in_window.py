"""After a failed run the Instructor says why, as `costar run` does: the status bar, the
failure button, the Log and the failed node's tooltip name the node the failure started at,
its error type and message, how many times it failed, the nodes that passed it up, and that
a plan that runs until success gave up after identical failures in a row.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from engine.files import dump_plan
from engine.status import Status
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window, node_named, run_to_end
from tests.instructor_app.runtime.plans import pick_behind_a_retry_plan

CAUSE = (
    "stopped after 2 identical failures in a row: grasp CUP failed 8 times (grasp_failed): "
    "nothing between the fingers; passed up by Retry 'pick 4 times', Selector 'pick or ask'"
)


def test_a_failed_run_names_the_root_cause_with_its_count_everywhere(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(pick_behind_a_retry_plan(give_up_after=2)), None)
    outcome = run_to_end(qtbot, window)
    assert outcome.status is Status.FAILURE
    ticks = outcome.event.tick
    assert window.statusBar().currentMessage() == f"Run ended: FAILURE after {ticks} ticks: {CAUSE}"
    pick = node_named(window, "grasp CUP")
    button = window.failure_button
    assert button.node_id == pick and button.text().startswith(
        "stopped after 2 identical failures in a row: grasp CUP failed 8 times"
    )
    assert CAUSE in button.toolTip()
    tip = window.views.canvas.tooltip_of(pick)
    assert tip == (
        "grasp CUP\nFailed: grasp_failed: nothing between the fingers (8 times); passed up by "
        "Retry 'pick 4 times', Selector 'pick or ask'; the run stopped after 2 identical "
        "failures in a row"
    )
    ask = window.views.canvas.tooltip_of(node_named(window, "ask for help"))
    assert ask.startswith("ask for help\nFailed: no one answered (2 times); passed up by Selector")
    lines = window.views.log.lines()
    assert any(
        line.endswith(f"Run of pick ended: FAILURE after {ticks} ticks: {CAUSE}") for line in lines
    )
    assert any(
        "On the way: ask for help failed 2 times: no one answered; passed up by Selector "
        "'pick or ask'" in line
        for line in lines
    )
