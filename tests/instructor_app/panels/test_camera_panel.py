"""The camera panel on the simulated cell: live pictures off the GUI thread, overlays from the
world model, snapshots, and a region drawn on a depth picture that is saved in the plan and
read by ``occupancy.is_occupied``.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt

from capabilities.base import CapabilityRegistry
from capabilities.occupancy import capability
from capabilities.sim.session import SimCellSession
from capabilities.world_model import Detection
from engine.spec import NodeKind, NodeSpec
from engine.types import Region
from instructor_app.document import PlanDocument
from instructor_app.document.regions import plan_regions, save_region
from instructor_app.panels.cameras import CameraPanel
from instructor_app.runtime.overlays import project
from tests.capabilities.occupancy.helpers import run_op


@pytest.fixture(scope="module")
def cell() -> Iterator[SimCellSession]:
    with SimCellSession("cup_to_bin", seed=0, shoulder_size=(320, 240)) as session:
        yield session


@pytest.fixture
def panel(qtbot, cell: SimCellSession) -> Iterator[CameraPanel]:
    widget = CameraPanel(fps=15.0)
    qtbot.addWidget(widget)
    widget.resize(900, 700)
    widget.set_cell(cell)
    widget.show()
    qtbot.waitUntil(lambda: {"shoulder", "wrist"} <= set(widget.shown), timeout=20000)
    yield widget
    widget.stop()


def _viewport_point(panel: CameraPanel, camera: str, u: float, v: float) -> QPoint:
    picture = panel._pictures[camera][1]
    scene_point = picture.mapToScene(QPointF(u, v))
    return panel.view.mapFromScene(scene_point)


def test_both_cameras_show_colour_and_depth_captured_off_the_gui_thread(panel: CameraPanel) -> None:
    assert panel.feed is not None and panel.feed.running
    for name in ("shoulder", "wrist"):
        shown = panel.shown[name]
        assert shown.rgb.shape == (240, 320, 3) and shown.depth.shape == (240, 320, 3)
        assert np.isfinite(shown.frame.depth).any()


def test_detections_of_the_world_model_are_outlined_with_class_and_confidence(
    qtbot, panel: CameraPanel, cell: SimCellSession
) -> None:
    before = panel.shown["shoulder"].seq
    assert panel.feed is not None
    newest = panel.feed.latest("shoulder")
    assert newest is not None
    plain = newest.frame.rgb  # the rendered picture, without overlays
    # A detection as the perception operations write it (its pose taken from the truth here,
    # in the test only).
    cell.world_model.replace("test", [Detection("cup", cell.truth_pose("cup"), 0.9, 0.0, "test")])
    try:
        # A frame painted after the detection arrived (the next one may have been painted
        # before); a generous bound: on a loaded machine a CPU-rendered frame takes ~0.5 s.
        qtbot.waitUntil(lambda: panel.shown["shoulder"].seq > before + 1, timeout=60000)
        shown = panel.shown["shoulder"]
        uv, _ = project(shown.frame, np.array([cell.truth_pose("cup").position]))
        u, v = (int(c) for c in uv[0])
        drawn = np.all(shown.rgb == (40, 255, 80), axis=2)  # the outline's colour
        assert drawn[max(v - 40, 0) : v + 40, max(u - 40, 0) : u + 40].sum() > 20
        assert not np.all(plain == (40, 255, 80), axis=2).any()
    finally:
        cell.world_model.replace("test", [])


def test_pause_stops_capturing_and_snapshot_writes_a_png(
    qtbot, panel: CameraPanel, tmp_path: Path
) -> None:
    panel.pause_button.setChecked(True)
    assert panel.feed is not None and panel.feed.active == frozenset()
    path = panel.snapshot(tmp_path / "cams.png")
    assert path is not None and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    panel.pause_button.setChecked(False)
    assert panel.feed.active == {"shoulder", "wrist"}


def test_a_region_drawn_on_the_depth_picture_is_saved_in_the_plan_and_read_by_is_occupied(
    qtbot, panel: CameraPanel, cell: SimCellSession
) -> None:
    document = PlanDocument()
    node = NodeSpec(NodeKind.OPERATION, "person near?", op="occupancy.is_occupied")
    document.add_node(node)
    before = document.serialized()
    panel.region_drawn.connect(lambda region: save_region(document, region, node.id))
    frame = panel.shown["shoulder"].frame
    # Where to point, in the test only: the cup's middle (its frame is at its foot).
    cup = np.add(cell.truth_pose("cup").position, (0.0, 0.0, 0.04))
    uv, _ = project(frame, cup[None, :])
    u, v = float(uv[0, 0]), float(uv[0, 1])
    panel.draw_button.setChecked(True)
    viewport = panel.view.viewport()
    with qtbot.waitSignal(panel.region_drawn, timeout=5000):
        qtbot.mousePress(
            viewport, Qt.MouseButton.LeftButton, pos=_viewport_point(panel, "shoulder", u, v)
        )
        qtbot.mouseMove(viewport, _viewport_point(panel, "shoulder", u + 12, v))
        qtbot.mouseMove(viewport, _viewport_point(panel, "shoulder", u + 25, v))
        qtbot.mouseRelease(
            viewport, Qt.MouseButton.LeftButton, pos=_viewport_point(panel, "shoulder", u + 25, v)
        )
    found = document.plan.find(node.id)
    assert found is not None
    region = found.params["region"].value
    assert isinstance(region, Region)
    assert np.linalg.norm(np.subtract(region.center, cup)) < 0.08  # a point on the cup
    assert 0.03 < region.radius < 0.3
    assert plan_regions(document.plan) == [("person near?", region)]
    registry = CapabilityRegistry([capability()], cell=cell)
    assert run_op(registry, "occupancy.is_occupied", region=region).ok  # the cup is in it
    empty = Region((region.center[0], region.center[1], region.center[2] + 0.6), 0.05)
    assert not run_op(registry, "occupancy.is_occupied", region=empty).ok
    document.undo_stack.undo()
    assert document.serialized() == before


def test_a_region_without_a_selected_region_node_becomes_a_plan_parameter(qapp: object) -> None:
    document = PlanDocument()
    where = save_region(document, Region((0.5, 0.0, 0.1), 0.1), None, "KEEP_OUT")
    assert where == "plan parameter KEEP_OUT"
    assert plan_regions(document.plan) == [("KEEP_OUT", Region((0.5, 0.0, 0.1), 0.1))]
    save_region(document, Region((0.6, 0.0, 0.1), 0.2), None, "KEEP_OUT")
    assert plan_regions(document.plan) == [("KEEP_OUT", Region((0.6, 0.0, 0.1), 0.2))]


def test_the_panel_says_when_a_live_view_stopped_and_the_other_camera_goes_on(qtbot) -> None:
    with SimCellSession("cup_to_bin", seed=0) as cell:
        widget = CameraPanel(fps=15.0)
        qtbot.addWidget(widget)
        widget.set_cell(cell)
        widget.show()
        qtbot.waitUntil(lambda: {"shoulder", "wrist"} <= set(widget.shown), timeout=30000)
        assert cell.live_view is not None
        os.kill(cell.live_view.pids()["shoulder"], signal.SIGKILL)  # the renderer crashes
        qtbot.waitUntil(lambda: "No live picture" in widget.rate_label.text(), timeout=20000)
        assert "shoulder" in widget.rate_label.text() and "stopped" in widget.rate_label.text()
        captions = {
            name: [x.toPlainText() for x in labels] for name, labels in widget._labels.items()
        }
        assert all("NO LIVE PICTURE" in text for text in captions["shoulder"])  # on the pictures
        assert not any("NO LIVE PICTURE" in text for text in captions["wrist"])
        wrist = widget.shown["wrist"].seq
        qtbot.waitUntil(lambda: widget.shown["wrist"].seq > wrist, timeout=20000)
        widget.stop()
