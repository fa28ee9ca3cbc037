"""Stop keeps the last statuses on the canvas until the next run, the running nodes shown as
halted; the status bar says "Running…", not "Run running".
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from engine.files import dump_plan
from engine.status import Status
from instructor_app.canvas.style import HALTED_COLOUR, STATUS_COLOURS
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window, node_named
from tests.instructor_app.runtime.plans import endless_plan


def test_stop_keeps_the_last_statuses_until_the_next_run(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(endless_plan()), None)
    canvas = window.views.canvas
    slow, top = node_named(window, "slow"), node_named(window, "top")
    window.run_actions.run.trigger()
    qtbot.waitUntil(lambda: canvas.status_of(slow) is Status.RUNNING)
    assert window.statusBar().currentMessage() == "Running…"
    with qtbot.waitSignal(window.controller.run_finished, timeout=10_000):
        window.run_actions.stop.trigger()
    # Where the run stopped stays visible, as halted (not amber: nothing runs any more); the
    # halt's resets do not grey the nodes.
    for node_id in (slow, top):
        assert canvas.is_halted(node_id) and canvas.status_of(node_id) is Status.RUNNING
        assert canvas.fill_of(node_id) == HALTED_COLOUR != STATUS_COLOURS[Status.RUNNING]
        assert "halted" in canvas.tooltip_of(node_id).lower()
    # The next run starts from grey.
    window.run_actions.run.trigger()
    assert canvas.status_of(top) in (Status.IDLE, None) and not canvas.is_halted(top)
    qtbot.waitUntil(lambda: canvas.status_of(slow) is Status.RUNNING)
    with qtbot.waitSignal(window.controller.run_finished, timeout=10_000):
        window.run_actions.stop.trigger()


def test_every_run_in_the_instructor_keeps_a_record_in_the_runs_folder(
    qtbot: Any, none_session: CellSession, tmp_path: Path, monkeypatch: Any
) -> None:
    """As `costar run` does: the record is the run's trace, in $COSTAR_RUNS (here a folder
    of the test's), and `costar runs list` names how the run ended.
    """
    from engine.run_records import list_records
    from engine.trace import read_trace

    runs = tmp_path / "runs"
    monkeypatch.setenv("COSTAR_RUNS", str(runs))
    window = make_window(qtbot, none_session, tmp_path)
    window.document.load_text(dump_plan(endless_plan()), None)
    slow = node_named(window, "slow")
    window.run_actions.run.trigger()
    qtbot.waitUntil(lambda: window.views.canvas.status_of(slow) is Status.RUNNING)
    with qtbot.waitSignal(window.controller.run_finished, timeout=10_000):
        window.run_actions.stop.trigger()
    record = window.controller.last_record
    assert record is not None and record.parent == runs
    trace = read_trace(record)
    assert trace.events[-1]["event"] == "finished" and trace.events[-1]["reason"] == "stopped"
    assert any(e.get("node") == slow and e.get("new") == "RUNNING" for e in trace.events)
    assert [s.path for s in list_records(runs)] == [record]
