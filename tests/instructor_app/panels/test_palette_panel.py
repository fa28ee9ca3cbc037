"""The palette: groups from the registry, search-to-insert, disabled items, drag data."""

from __future__ import annotations

import json

from PySide6.QtCore import Qt
from pytestqt.qtbot import QtBot

from capabilities.base import CapabilityRegistry, NullCell
from capabilities.debug import capability as debug_capability
from engine.spec import NodeKind
from instructor_app.node_factory import PALETTE_MIME, PaletteItem
from instructor_app.panels.palette import PalettePanel


def _row(panel: PalettePanel, label: str):
    found = panel.tree.findItems(label, Qt.MatchFlag.MatchExactly | Qt.MatchFlag.MatchRecursive)
    assert len(found) == 1, label
    return found[0]


def test_groups_come_from_logic_kinds_and_capabilities(
    qtbot: QtBot, registry: CapabilityRegistry
) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    assert panel.groups() == ["Composites", "Decorators", "Leaves", "Debug", "Template"]
    assert len(panel.visible_items()) == len(panel.items())


def test_set_registry_rebuilds(qtbot: QtBot, registry: CapabilityRegistry) -> None:
    panel = PalettePanel(CapabilityRegistry([debug_capability()], cell=NullCell()))
    qtbot.addWidget(panel)
    assert "Template" not in panel.groups()
    panel.set_registry(registry)
    assert "Template" in panel.groups()


def test_search_filters_as_you_type_and_enter_inserts_first_match(
    qtbot: QtBot, registry: CapabilityRegistry
) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    qtbot.keyClicks(panel.search_field, "pretend")
    assert [i.op for i in panel.visible_items()] == ["debug.pretend_move"]
    assert panel.groups() == ["Composites", "Decorators", "Leaves", "Debug", "Template"]
    assert [g for g in range(5) if not panel.tree.topLevelItem(g).isHidden()] == [3]
    with qtbot.waitSignal(panel.item_activated) as blocker:
        qtbot.keyClick(panel.search_field, Qt.Key.Key_Return)
    assert blocker.args[0].op == "debug.pretend_move"
    panel.search_field.clear()
    assert len(panel.visible_items()) == len(panel.items())
    with qtbot.assertNotEmitted(panel.item_activated):
        qtbot.keyClick(panel.search_field, Qt.Key.Key_Return)


def test_enter_on_search_skips_unavailable_matches(
    qtbot: QtBot, registry: CapabilityRegistry
) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    qtbot.keyClicks(panel.search_field, "lamp")
    assert [i.op for i in panel.visible_items()] == ["template.lamp_is_lit"]
    with qtbot.assertNotEmitted(panel.item_activated):
        qtbot.keyClick(panel.search_field, Qt.Key.Key_Return)


def test_unavailable_item_is_greyed_with_reason_and_not_insertable(
    qtbot: QtBot, registry: CapabilityRegistry
) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    row = _row(panel, "Lamp is lit")
    assert not row.flags() & Qt.ItemFlag.ItemIsEnabled
    assert not row.flags() & Qt.ItemFlag.ItemIsDragEnabled
    assert "lamp" in row.toolTip(0) and row.toolTip(0).startswith("Not available")
    with qtbot.assertNotEmitted(panel.item_activated):
        panel.tree.itemDoubleClicked.emit(row, 0)


def test_double_click_and_enter_insert(qtbot: QtBot, registry: CapabilityRegistry) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    panel.show()
    row = _row(panel, "Retry")
    panel.tree.scrollToItem(row)
    rect = panel.tree.visualItemRect(row)
    # An item view takes a double click only after the press of its first click.
    qtbot.mouseClick(panel.tree.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    with qtbot.waitSignal(panel.item_activated) as blocker:
        qtbot.mouseDClick(panel.tree.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    assert blocker.args[0].kind is NodeKind.RETRY
    panel.tree.setCurrentItem(_row(panel, "Succeed"))
    with qtbot.waitSignal(panel.item_activated) as blocker:
        qtbot.keyClick(panel.tree, Qt.Key.Key_Return)
    assert isinstance(blocker.args[0], PaletteItem) and blocker.args[0].op == "debug.succeed"


def test_drag_mime_data(qtbot: QtBot, registry: CapabilityRegistry) -> None:
    panel = PalettePanel(registry)
    qtbot.addWidget(panel)
    mime = panel.tree.mimeData([_row(panel, "Query")])
    assert PALETTE_MIME in mime.formats()
    assert json.loads(bytes(mime.data(PALETTE_MIME)).decode()) == {
        "kind": "operation",
        "op": "debug.query",
    }
    logic = panel.tree.mimeData([_row(panel, "Parallel")])
    assert json.loads(bytes(logic.data(PALETTE_MIME)).decode()) == {"kind": "parallel", "op": None}
