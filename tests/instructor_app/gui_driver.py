"""Drive the Instructor like a user: palette double-clicks, inspector fields, the run button.

For the window tests and the end-to-end test (build a plan from an empty document, save,
reopen, run). Every helper goes through widgets and their signals, not private methods.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from PySide6.QtCore import QSettings, Qt
from PySide6.QtWidgets import QTreeWidgetItem, QWidget

from engine.types import ParamType
from instructor_app.inspectors.rows import MODE_REFERENCE, MODE_VALUE, PortRow
from instructor_app.main_window import DISCARD, Dialogs, MainWindow
from instructor_app.runtime.controller import RunOutcome
from instructor_app.runtime.session import CellSession
from instructor_app.settings import AppSettings

__all__ = [
    "ScriptedDialogs",
    "make_window",
    "palette_row",
    "add_from_palette",
    "select",
    "rename",
    "bind_reference",
    "set_value",
    "run_to_end",
    "node_named",
]


class ScriptedDialogs(Dialogs):
    """Answers the window's questions from lists and records what was asked.

    Attributes:
        save_answers: answers to "save the changes?" ("save", "discard", "cancel"); when
            empty, "discard".
        restore_answers: answers to "restore the unsaved plan?"; when empty, False.
        open_paths / save_paths: what the file dialogs return ("" = cancelled).
        asked: ("save" | "restore", text) in order; errors: (title, text) in order.
    """

    def __init__(self) -> None:
        self.save_answers: list[str] = []
        self.restore_answers: list[bool] = []
        self.open_paths: list[str] = []
        self.save_paths: list[str] = []
        self.asked: list[tuple[str, str]] = []
        self.errors: list[tuple[str, str]] = []

    def ask_save_changes(self, parent: QWidget, name: str) -> str:
        self.asked.append(("save", name))
        return self.save_answers.pop(0) if self.save_answers else DISCARD

    def ask_restore(self, parent: QWidget, description: str) -> bool:
        self.asked.append(("restore", description))
        return self.restore_answers.pop(0) if self.restore_answers else False

    def error(self, parent: QWidget, title: str, text: str) -> None:
        self.errors.append((title, text))

    def open_path(self, parent: QWidget, folder: str) -> str:
        return self.open_paths.pop(0) if self.open_paths else ""

    def save_path(self, parent: QWidget, suggested: str) -> str:
        return self.save_paths.pop(0) if self.save_paths else ""

    def about(self, parent: QWidget, text: str) -> None:
        self.asked.append(("about", text))


def make_window(
    qtbot: Any,
    session: CellSession,
    folder: Path,
    dialogs: Dialogs | None = None,
    autosave_ms: int = 60_000,
    rate_hz: float = 100.0,
) -> MainWindow:
    """A shown window with settings and recovery files under ``folder`` (never the user's)."""
    settings = AppSettings(QSettings(str(folder / "settings.ini"), QSettings.Format.IniFormat))
    window = MainWindow(
        session,
        settings,
        dialogs or ScriptedDialogs(),
        folder / "recovery",
        autosave_interval_ms=autosave_ms,
        rate_hz=rate_hz,
    )
    qtbot.addWidget(window)
    window.show()
    qtbot.waitExposed(window)
    return window


def palette_row(window: MainWindow, key: str) -> QTreeWidgetItem:
    """The palette row whose operation id, kind or label is ``key``."""
    palette = window.views.palette
    item = next(i for i in palette.items() if key in (i.op, i.kind.value, i.label))
    flags = Qt.MatchFlag.MatchExactly | Qt.MatchFlag.MatchRecursive
    for row in palette.tree.findItems(item.label, flags):
        group = row.parent()
        if group is not None and group.text(0).lower() == item.group.replace("_", " ").lower():
            return row
    raise LookupError(f"the palette shows no row for {key!r}")


def add_from_palette(qtbot: Any, window: MainWindow, key: str) -> str:
    """Pick a palette row and press Enter; returns the id of the node it added."""
    before = _ids(window)
    tree = window.views.palette.tree
    tree.setCurrentItem(palette_row(window, key))
    qtbot.keyClick(tree, Qt.Key.Key_Return)
    added = [i for i in _ids(window) if i not in before]
    assert len(added) == 1, f"inserting {key!r} from the palette added {len(added)} nodes"
    return added[0]


def select(window: MainWindow, node_id: str) -> None:
    """Select a node on the canvas (as a click on it would)."""
    window.views.canvas.select(node_id)
    assert window.views.inspector.shown_node_id() == node_id


def rename(qtbot: Any, window: MainWindow, node_id: str, name: str) -> None:
    select(window, node_id)
    field = window.views.inspector.name_field
    field.selectAll()
    qtbot.keyClicks(field, name)
    qtbot.keyClick(field, Qt.Key.Key_Return)


def bind_reference(qtbot: Any, window: MainWindow, node_id: str, port: str, name: str) -> None:
    """Bind a port to a named parameter (inputs: choose "parameter" first)."""
    select(window, node_id)
    row: PortRow = window.views.inspector.port_row(port)
    if row.mode_combo.count():
        _choose_mode(row, MODE_REFERENCE)
    row.ref_field.clear()
    qtbot.keyClicks(row.ref_field, name)
    qtbot.keyClick(row.ref_field, Qt.Key.Key_Return)


def set_value(
    window: MainWindow, node_id: str, port: str, value: Any, ptype: ParamType | None = None
) -> None:
    """Give a port a fixed value through its editor (as if typed and committed)."""
    select(window, node_id)
    row: PortRow = window.views.inspector.port_row(port)
    if ptype is not None and ptype is not row.value_type:
        index = row.types.index(ptype)
        row.type_combo.setCurrentIndex(index)
        row.type_combo.activated.emit(index)
    _choose_mode(row, MODE_VALUE)
    row = window.views.inspector.port_row(port)
    assert row.editor is not None
    row.editor.set_value(value)
    row.editor.value_committed.emit(value)  # what the editor says when the user is done


def _choose_mode(row: PortRow, mode: int) -> None:
    if row.mode != mode:
        row.mode_combo.setCurrentIndex(mode)
        row.mode_combo.activated.emit(mode)


def run_to_end(qtbot: Any, window: MainWindow, timeout_ms: int = 30_000) -> RunOutcome:
    """Press Run and wait for the run to finish; the outcome."""
    with qtbot.waitSignal(window.controller.run_finished, timeout=timeout_ms) as blocker:
        window.run_actions.run.trigger()
    return blocker.args[0]


def node_named(window: MainWindow, name: str) -> str:
    return next(n.id for _, n in window.document.plan.walk() if n.name == name)


def _ids(window: MainWindow) -> Iterable[str]:
    return [n.id for _, n in window.document.plan.walk()]
