"""An idle cell keeps the views quiet (issue 26): with nothing in view moving the simulated
cell's live view renders nothing, the camera feed leaves no new frame and the camera panel's
timer stops; a move makes frames come again. The mechanism is tested, not a CPU figure
(``bench/gui.py`` measures ``idle_cpu_cores``).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from PySide6.QtCore import QObject, Signal

from capabilities.sim.session import SimCellSession
from instructor_app.panels.cameras import CameraPanel
from instructor_app.runtime.robot_status import IDLE_INTERVAL_MS, IDLE_READS, RobotStatusLabel


@pytest.fixture(scope="module")
def cell() -> Iterator[SimCellSession]:
    with SimCellSession("cup_to_bin", seed=0, speed=1.0) as session:
        yield session


@pytest.fixture
def panel(qtbot, cell: SimCellSession) -> Iterator[CameraPanel]:
    widget = CameraPanel(fps=15.0)
    qtbot.addWidget(widget)
    widget.resize(700, 500)
    widget.set_cell(cell)
    widget.show()
    qtbot.waitUntil(lambda: {"shoulder", "wrist"} <= set(widget.shown), timeout=30000)
    yield widget
    widget.stop()


def _renders(cell: SimCellSession) -> int:
    assert cell.live_view is not None
    return sum(cell.live_view.requests().values())


def test_an_idle_cell_renders_nothing_and_the_camera_timer_stops_until_something_moves(
    qtbot, cell: SimCellSession, panel: CameraPanel
) -> None:
    feed = panel.feed
    assert feed is not None
    # The scene settles (objects come to rest), then the panel's timer stops by itself.
    qtbot.waitUntil(lambda: not panel.polling, timeout=30000)
    shown, renders, looks = panel.frames_shown, _renders(cell), feed.unchanged
    # The feed keeps looking (some 15 times a second per camera) and finds nothing new:
    qtbot.waitUntil(lambda: feed.unchanged >= looks + 40, timeout=20000)
    assert panel.frames_shown == shown, "an idle cell showed new pictures"
    assert _renders(cell) == renders, "the live view rendered an unchanged cell"
    assert not panel.polling, "the camera panel's timer ran while nothing came"

    arm = cell.interfaces()["arm"]
    q = list(arm.joint_positions())
    q[0] += 0.4
    handle = arm.move_joints(q, speed=0.5)
    qtbot.waitUntil(lambda: panel.frames_shown >= shown + 4, timeout=20000)
    assert _renders(cell) > renders
    handle.wait(30.0)
    # Still again: the timer stops again and the rendering with it.
    qtbot.waitUntil(lambda: not panel.polling, timeout=30000)
    renders = _renders(cell)
    looks = feed.unchanged
    qtbot.waitUntil(lambda: feed.unchanged >= looks + 20, timeout=20000)
    assert _renders(cell) == renders


class _Session(QObject):
    """What RobotStatusLabel reads of a cell session: the open cell and its change signal."""

    cell_changed = Signal(str)

    def __init__(self, cell: object) -> None:
        super().__init__()
        self.cell = cell


def test_the_robot_status_is_read_slowly_while_it_does_not_change(
    qtbot, cell: SimCellSession
) -> None:
    label = RobotStatusLabel(_Session(cell), interval_ms=10)  # type: ignore[arg-type]
    qtbot.addWidget(label)
    assert label.interval_ms == 10
    for _ in range(IDLE_READS):
        label.refresh()
    assert label.interval_ms == IDLE_INTERVAL_MS
