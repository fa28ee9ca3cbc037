"""Labels stay readable at the zoom Fit chooses: a 30-node plan fitted into a 1400x900 window
shows every node's title as painted text (dark glyph pixels inside each box of the grabbed
viewport), never a blank box; a plan too wide for a readable zoom shows its top around the
root. Unknown operations are drawn as broken (a red dashed border) with a tooltip.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import QRect
from PySide6.QtGui import QImage

from engine.files import dump_plan
from engine.spec import NodeKind, NodeSpec, PlanSpec
from instructor_app.canvas.items import DETAIL_LOD
from instructor_app.canvas.view import MIN_FIT_ZOOM
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import make_window
from tests.instructor_app.runtime.plans import op

_GLYPH_MAX = 60  # a pixel darker than this in every channel is ink of the text colour


def _seq(name: str, *children: NodeSpec) -> NodeSpec:
    return NodeSpec(NodeKind.SEQUENCE, name=name, children=list(children))


def _leaves(prefix: str, count: int) -> list[NodeSpec]:
    return [op("debug.succeed", f"{prefix} step {i + 1}") for i in range(count)]


def thirty_node_plan() -> PlanSpec:
    """30 nodes in the shape of a tending plan: prepare, a transfer that falls back to a
    wait, finish; pick and place nested under the transfer.
    """
    transfer = NodeSpec(
        NodeKind.SELECTOR,
        name="transfer or wait",
        children=[
            _seq(
                "transfer", _seq("pick", *_leaves("pick", 6)), _seq("place", *_leaves("place", 5))
            ),
            NodeSpec(
                NodeKind.FORCE_FAILURE, name="look again", children=[op("debug.succeed", "WAIT")]
            ),
        ],
    )
    top = _seq("tend the cell", _seq("prepare", *_leaves("prepare", 5)), transfer,
               _seq("finish", *_leaves("finish", 5)))  # fmt: skip
    return PlanSpec(tree=top, name="tending")


def wide_plan() -> PlanSpec:
    """30 nodes, 25 of them leaves side by side: too wide to fit at a readable zoom."""
    groups = [_seq(f"group {g}", *_leaves(f"g{g}", 5 if g else 4)) for g in range(5)]
    return PlanSpec(tree=_seq("top", *groups), name="wide")


def _viewport_rect(window: MainWindow, node_id: str) -> QRect:
    """Where a node's body shows in the viewport."""
    canvas = window.views.canvas
    item = canvas.item(node_id)
    scene_rect = item.mapToScene(item.shape_rect()).boundingRect()
    return canvas.viewer.mapFromScene(scene_rect).boundingRect()


def _ink_rows(image: QImage, rect: QRect) -> set[int]:
    """Rows of ``rect`` (shrunk by 3 px: no border) that hold dark glyph pixels."""
    rows: set[int] = set()
    inner = rect.adjusted(3, 3, -3, -3).intersected(image.rect())
    for y in range(inner.top(), inner.bottom() + 1):
        for x in range(inner.left(), inner.right() + 1):
            colour = image.pixelColor(x, y)
            if max(colour.red(), colour.green(), colour.blue()) < _GLYPH_MAX:
                rows.add(y)
                break
    return rows


def _fitted(qtbot: Any, window: MainWindow, plan: PlanSpec) -> tuple[list[str], QImage]:
    window.resize(1400, 900)
    qtbot.waitUntil(lambda: window.width() == 1400)
    window.document.load_text(dump_plan(plan), None)
    ids = [n.id for _, n in window.document.plan.walk()]
    assert len(ids) == 30
    window.actions_by_name["fit"].trigger()
    return ids, window.views.canvas.viewer.viewport().grab().toImage()


def _assert_label_painted(window: MainWindow, image: QImage, node_id: str) -> None:
    canvas = window.views.canvas
    item = canvas.item(node_id)
    scale = canvas.viewer.transform().m11()
    box = item.overview_rect(scale) if scale < DETAIL_LOD else item.shape_rect()
    rect = canvas.viewer.mapFromScene(item.mapToScene(box).boundingRect()).boundingRect()
    rows = _ink_rows(image, rect)
    label = window.document.node(node_id).label
    # ink on at least 5 rows: the x-height of a small screen font, not specks or a box
    assert len(rows) >= 5, f"{label!r}: {len(rows)} rows of text painted"


def test_fitted_30_node_plan_has_every_label_painted(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    ids, image = _fitted(qtbot, window, thirty_node_plan())
    canvas = window.views.canvas
    assert all(canvas.is_visible_in_view(i) for i in ids)
    assert canvas.viewer.transform().m11() >= MIN_FIT_ZOOM * 0.99
    for node_id in ids:
        _assert_label_painted(window, image, node_id)


def test_fit_of_a_too_wide_plan_stays_readable_around_the_root(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    ids, image = _fitted(qtbot, window, wide_plan())
    canvas = window.views.canvas
    assert abs(canvas.viewer.transform().m11() - MIN_FIT_ZOOM) < 0.01
    shown = [i for i in ids if canvas.is_visible_in_view(i)]
    tree = window.document.plan.tree
    assert tree is not None and tree.id in shown and len(shown) >= 8
    for node_id in shown:
        _assert_label_painted(window, image, node_id)


def test_unknown_operation_is_drawn_broken(
    qtbot: Any, none_session: CellSession, tmp_path: Path
) -> None:
    window = make_window(qtbot, none_session, tmp_path)
    ghost = op("debug.no_such_thing", "ghost")
    plan = PlanSpec(
        tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=[ghost, op("debug.succeed")])
    )
    window.document.load_text(dump_plan(plan), None)
    canvas = window.views.canvas
    item = canvas.item(ghost.id)
    assert "unknown operation" in item.toolTip().lower()
    tree = window.document.plan.tree
    assert tree is not None
    fine = canvas.item(tree.children[1].id)
    assert fine.toolTip() == "" or "unknown" not in fine.toolTip().lower()
    # The painted border is red (the broken look), the other leaf's is not.
    canvas.center_on(ghost.id)
    image = canvas.viewer.viewport().grab().toImage()

    def red_pixels(node_id: str) -> int:
        rect = _viewport_rect(window, node_id)
        count = 0
        for y in range(rect.top(), rect.bottom() + 1):
            for x in (rect.left(), rect.left() + 1, rect.right(), rect.right() - 1):
                colour = image.pixelColor(x, y)
                count += colour.red() > 150 and colour.green() < 90 and colour.blue() < 90
        return count

    assert red_pixels(ghost.id) > 10
    assert red_pixels(fine.id) == 0
