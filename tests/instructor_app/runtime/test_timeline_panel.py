"""The Timeline panel: a record of a `costar run` opened in the window shows each moment's
statuses on the canvas, the nodes running then, the values, and goes to a failure's moment
when its mark is clicked.
"""

from __future__ import annotations

import base64
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtGui import QColor

from capabilities.cli import main as costar
from capabilities.run_sampler import thumbnail_jpeg
from engine.files import save_plan
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import ScriptedDialogs, make_window, node_named, run_to_end
from tests.instructor_app.runtime.plans import number, op, text


def _plan() -> PlanSpec:
    """Waits 10 ticks, writes a name, then a grasp fails twice behind a retry and "ask"
    takes over: a run with RUNNING moments, a blackboard write and two failures.
    """
    wait = op("debug.running", "wait", ticks=number(10))
    grasp = op("debug.fail", "grasp CUP", message=text("nothing between the fingers"))
    retry = NodeSpec(
        NodeKind.RETRY, name="pick twice", params={"count": number(2)}, children=[grasp]
    )
    fallback = NodeSpec(
        NodeKind.SELECTOR, name="pick or ask", children=[retry, op("debug.succeed", "ask")]
    )
    return PlanSpec(NodeSpec(NodeKind.SEQUENCE, name="top", children=[wait, fallback]), "timed")


@pytest.fixture
def record(tmp_path: Path) -> Path:
    """The record of a `costar run` of the plan on no cell."""
    plan = tmp_path / "timed.costar.json"
    save_plan(_plan(), plan)
    runs = tmp_path / "runs"
    out, err = io.StringIO(), io.StringIO()
    code = costar(
        ["run", "--cell", "none", str(plan), "--rate", "100", "--runs", str(runs)], out, err
    )
    assert code == 0, err.getvalue()
    (path,) = runs.iterdir()
    return path


@pytest.fixture
def window(qtbot: Any, none_session: CellSession, tmp_path: Path) -> MainWindow:
    return make_window(qtbot, none_session, tmp_path, ScriptedDialogs())


def _open(window: MainWindow, record: Path) -> None:
    dialogs = window.dialogs
    assert isinstance(dialogs, ScriptedDialogs)
    dialogs.record_paths.append(str(record))
    window.actions_by_name["open_record"].trigger()


def test_a_moment_of_the_record_shows_its_statuses_on_the_canvas(
    qtbot: Any, window: MainWindow, record: Path
) -> None:
    _open(window, record)
    panel, canvas = window.views.timeline, window.views.canvas
    assert panel.timeline is not None and window.document.plan.name == "timed"
    wait, grasp = node_named(window, "wait"), node_named(window, "grasp CUP")
    top = window.document.plan.tree.id
    # The middle of the wait: "top" and "wait" run, the grasp has not started.
    timeline = panel.timeline
    started = timeline.figures(wait)
    assert started.starts == 1 and started.ticks >= 10
    moment = timeline.failures[0].time / 2
    panel.slider.setValue(round(moment * 1000))
    qtbot.waitUntil(lambda: canvas.status_of(wait) is Status.RUNNING)
    assert canvas.status_of(top) is Status.RUNNING
    assert canvas.status_of(grasp) in (None, Status.IDLE)
    assert panel.running.node_ids()[:3] == ["root", top, wait]  # the run's own root first
    assert panel.running.item(0).text() == "the run of timed"
    assert "s / " in panel.time_label.text()
    # The end: everything succeeded but the grasp, which failed last.
    panel.show_time(timeline.duration)
    assert canvas.status_of(top) is Status.SUCCESS
    assert canvas.status_of(grasp) is Status.FAILURE
    assert panel.running.count() == 0
    # Back to the start: the statuses go back too.
    panel.show_time(0.0)
    assert canvas.status_of(grasp) in (None, Status.IDLE)


def test_clicking_a_failure_mark_goes_to_that_failure(
    qtbot: Any, window: MainWindow, record: Path
) -> None:
    _open(window, record)
    window.raise_dock("timeline")
    panel, canvas = window.views.timeline, window.views.canvas
    timeline = panel.timeline
    assert timeline is not None and len(timeline.failures) >= 2
    grasp = node_named(window, "grasp CUP")
    assert {m.node_id for m in timeline.failures} == {grasp}
    panel.show_time(timeline.duration)
    slider = panel.slider
    qtbot.waitExposed(slider)
    mark = slider.marks()[0]
    x = slider.mark_x(mark)
    qtbot.mouseClick(slider, Qt.MouseButton.LeftButton, pos=QPoint(x, slider.height() // 2))
    qtbot.waitUntil(lambda: slider.value() == mark)
    qtbot.waitUntil(lambda: canvas.status_of(grasp) is Status.FAILURE)
    assert abs(panel.time - timeline.failures[0].time) < 0.002


def test_the_selected_node_shows_its_figures_and_last_run_opens_the_newest_record(
    qtbot: Any, window: MainWindow, record: Path, monkeypatch: Any
) -> None:
    monkeypatch.setenv("COSTAR_RUNS", str(record.parent))
    window.views.timeline.last_button.click()
    panel = window.views.timeline
    assert panel.timeline is not None and panel.timeline.name == record.name
    grasp = node_named(window, "grasp CUP")
    window.views.canvas.select(grasp)
    qtbot.waitUntil(lambda: "grasp CUP" in panel.figures_label.text())
    assert "2 failures" in panel.figures_label.text()
    assert "started 2" in panel.figures_label.text()


def test_last_run_opens_the_record_of_the_run_that_just_ended_and_a_run_closes_it(
    qtbot: Any, window: MainWindow, figure3_path: Path
) -> None:
    window.open_plan(figure3_path)
    run_to_end(qtbot, window)
    panel = window.views.timeline
    panel.last_button.click()
    record = window.controller.last_record
    assert record is not None and panel.timeline is not None
    assert panel.timeline.name == record.name
    assert window.document.path == figure3_path  # the same plan: the canvas keeps it
    cup_found = node_named(window, "CUP found")
    panel.go_to_failure(0)
    assert window.views.canvas.status_of(cup_found) is Status.FAILURE
    assert window.document.plan.tree.id in panel.running.node_ids()  # the plan went on
    run_to_end(qtbot, window)
    assert panel.timeline is None and not panel.slider.isEnabled()


def test_a_moment_shows_the_values_and_the_robots_joints_of_that_moment(
    qtbot: Any, window: MainWindow, figure3_path: Path, tmp_path: Path, monkeypatch: Any
) -> None:
    runs = tmp_path / "runs"
    code = costar(
        ["run", "--cell", "none", str(figure3_path), "--rate", "200", "--runs", str(runs)],
        io.StringIO(),
        io.StringIO(),
    )
    assert code == 0
    (record,) = runs.iterdir()
    with record.open("a", encoding="utf-8") as out:  # what a cell's arm adds, 10 times a second
        start = json.loads(record.read_text().splitlines()[1])["time"]  # the run's start
        for i in range(5):
            out.write(f'{{"event":"joints","q":[{i},0,0,0,0,0],"time":{start + 0.1 * i}}}\n')
    ghosts: list[Any] = []
    monkeypatch.setattr(window.cell_views.scene3d, "show_ghost", ghosts.append)
    _open(window, record)
    panel, blackboard = window.views.timeline, window.views.blackboard
    assert panel.timeline is not None
    panel.show_time(0.25)
    assert ghosts[-1] == [2.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    panel.show_time(panel.timeline.duration)
    assert {"CUP_POSE", "BIN_POSE"} <= set(blackboard.values())
    panel.show_time(0.0)
    assert not {"CUP_POSE", "BIN_POSE"} & set(blackboard.values())
    assert ghosts[-1] == [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]


def test_play_goes_on_through_the_run_and_stops_at_its_end(
    qtbot: Any, window: MainWindow, record: Path
) -> None:
    _open(window, record)
    panel = window.views.timeline
    assert panel.timeline is not None and not panel.playing
    panel.play_button.click()
    assert panel.playing
    qtbot.waitUntil(lambda: not panel.playing, timeout=5000)  # the run lasts about 0.12 s
    assert panel.slider.value() == panel.slider.maximum()
    assert not panel.play_button.isChecked()


def test_a_moment_shows_the_cameras_pictures_of_that_moment(
    qtbot: Any, window: MainWindow, record: Path
) -> None:
    start = json.loads(record.read_text().splitlines()[1])["time"]  # the run's start
    with record.open("a", encoding="utf-8") as out:  # what a cell's cameras add, once a second
        for i, grey in enumerate((40, 200)):
            jpeg = thumbnail_jpeg(np.full((120, 160, 3), grey, np.uint8))
            line = {"event": "thumbnail", "camera": "wrist", "jpeg": "", "time": start + 0.05 * i}
            out.write(json.dumps(line | {"jpeg": base64.b64encode(jpeg).decode()}) + "\n")
    _open(window, record)
    panel = window.views.timeline
    assert list(panel.picture_labels) == ["wrist"]
    panel.show_time(0.0)
    dark = panel.picture("wrist")
    assert dark is not None and (dark.width(), dark.height()) == (160, 120)
    assert QColor(dark.toImage().pixel(80, 60)).red() < 100
    panel.show_time(0.06)
    light = panel.picture("wrist")
    assert light is not None and QColor(light.toImage().pixel(80, 60)).red() > 150
    out_, err_ = io.StringIO(), io.StringIO()  # a reader that knows no pictures goes on
    assert costar(["runs", "show", str(record)], out_, err_) == 0, err_.getvalue()
    assert "thumbnail" not in out_.getvalue() and "run finished" in out_.getvalue()


def test_the_runs_folder_is_a_setting_that_runs_and_last_run_use(
    qtbot: Any, none_session: CellSession, figure3_path: Path, tmp_path: Path, monkeypatch: Any
) -> None:
    monkeypatch.delenv("COSTAR_RUNS")  # the variable would override the setting
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, none_session, tmp_path, dialogs)
    chosen = tmp_path / "chosen runs"
    dialogs.folder_answers.append(str(chosen))
    window.actions_by_name["runs_folder"].trigger()
    assert window.settings.runs_folder() == str(chosen)
    window.open_plan(figure3_path)
    run_to_end(qtbot, window)
    record = window.controller.last_record
    assert record is not None and record.parent == chosen
    window.close()
    again = make_window(qtbot, none_session, tmp_path, ScriptedDialogs())  # the same settings
    assert again.controller.runs_folder() == chosen
    again.views.timeline.last_button.click()  # no run in this window: the folder's newest
    timeline = again.views.timeline.timeline
    assert timeline is not None and timeline.name == record.name
    monkeypatch.setenv("COSTAR_RUNS", str(tmp_path / "env"))
    assert again.controller.runs_folder() == tmp_path / "env"
