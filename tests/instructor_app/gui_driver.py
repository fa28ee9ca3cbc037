"""Drive the Instructor like a user: palette search and double-clicks, canvas clicks,
inspector fields, the plan panels, the run button.

For the window tests and the end-to-end test (build a plan from an empty document, save,
reopen, run). Every helper goes through widgets: keys typed into fields, combo entries chosen
with the keyboard, buttons clicked. Only editors without a typed path (pose, region, joints
grids) get their value set and committed through the editor's own signal.

Pass a :class:`CountingBot` in place of ``qtbot`` to count what the user did.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from PySide6.QtCore import QPointF, QSettings, Qt
from PySide6.QtGui import QDropEvent
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QTabBar,
    QToolBar,
    QTreeWidgetItem,
    QWidget,
)

from engine.spec import NodeSpec, RunPolicy
from engine.types import ObjectModel, ParamType, Waypoint
from instructor_app.inspectors.base import ParamEditor
from instructor_app.inspectors.editors import (
    ChoiceEditor,
    NumberEditor,
    ObjectModelEditor,
    TextEditor,
    WaypointEditor,
)
from instructor_app.inspectors.rows import MODE_REFERENCE, MODE_UNSET, MODE_VALUE, PortRow
from instructor_app.main_window import DISCARD, Dialogs, MainWindow
from instructor_app.panels.plan_settings import POLICY_TEXT, PlanSettingsPanel
from instructor_app.panels.waypoints import WaypointsPanel
from instructor_app.runtime.controller import RunOutcome
from instructor_app.runtime.session import CellSession
from instructor_app.settings import AppSettings

__all__ = [
    "CountingBot",
    "ScriptedDialogs",
    "make_window",
    "palette_row",
    "add_from_palette",
    "search_insert",
    "search_down_insert",
    "double_click_palette",
    "show_tab",
    "drag_object_onto",
    "select",
    "click_node",
    "choose",
    "choose_index",
    "rename",
    "bind_reference",
    "set_value",
    "unset",
    "plan_panels",
    "set_run_policy",
    "set_plan_name",
    "import_waypoints",
    "press_run",
    "run_to_end",
    "node_named",
]


class ScriptedDialogs(Dialogs):
    """Answers the window's questions from lists and records what was asked.

    Attributes:
        save_answers: answers to "save the changes?" ("save", "discard", "cancel"); when
            empty, "discard".
        restore_answers: answers to "restore the unsaved plan?"; when empty, False.
        overwrite_answers: answers to "teach again a waypoint other nodes use?"; when
            empty, False.
        open_paths / save_paths / cell_paths / record_paths: what the file dialogs return ("" = cancelled).
        port_answers: what the Groot2 port dialog returns (None = cancelled; when empty, None).
        text_answers: what a line-of-text question returns (None = cancelled; when empty,
            None).
        asked: ("save" | "restore" | "overwrite", text) in order; errors: (title, text) in order.
    """

    def __init__(self) -> None:
        self.save_answers: list[str] = []
        self.restore_answers: list[bool] = []
        self.overwrite_answers: list[bool] = []
        self.open_paths: list[str] = []
        self.save_paths: list[str] = []
        self.cell_paths: list[str] = []
        self.record_paths: list[str] = []
        self.asked: list[tuple[str, str]] = []
        self.errors: list[tuple[str, str]] = []
        self.port_answers: list[int | None] = []
        self.text_answers: list[str | None] = []
        self.folder_answers: list[str | None] = []

    def ask_save_changes(self, parent: QWidget, name: str) -> str:
        self.asked.append(("save", name))
        return self.save_answers.pop(0) if self.save_answers else DISCARD

    def ask_groot2_port(self, parent: QWidget, current: int) -> int | None:
        self.asked.append(("groot2_port", str(current)))
        return self.port_answers.pop(0) if self.port_answers else None

    def ask_text(self, parent: QWidget, title: str, label: str, text: str) -> str | None:
        self.asked.append(("text", title))
        return self.text_answers.pop(0) if self.text_answers else None

    def ask_runs_folder(self, parent: QWidget, current: str) -> str | None:
        self.asked.append(("runs_folder", current))
        return self.folder_answers.pop(0) if self.folder_answers else None

    def ask_restore(self, parent: QWidget, description: str) -> bool:
        self.asked.append(("restore", description))
        return self.restore_answers.pop(0) if self.restore_answers else False

    def ask_overwrite_waypoint(self, parent: QWidget, name: str, users: list[str]) -> bool:
        self.asked.append(("overwrite", f"{name}: {', '.join(users)}"))
        return self.overwrite_answers.pop(0) if self.overwrite_answers else False

    def error(self, parent: QWidget, title: str, text: str) -> None:
        self.errors.append((title, text))

    def open_path(self, parent: QWidget, folder: str) -> str:
        return self.open_paths.pop(0) if self.open_paths else ""

    def record_open_path(self, parent: QWidget, folder: str) -> str:
        return self.record_paths.pop(0) if self.record_paths else ""

    def open_cell_path(self, parent: QWidget, folder: str) -> str:
        return self.cell_paths.pop(0) if self.cell_paths else ""

    def save_path(self, parent: QWidget, suggested: str) -> str:
        return self.save_paths.pop(0) if self.save_paths else ""

    def about(self, parent: QWidget, text: str) -> None:
        self.asked.append(("about", text))


class CountingBot:
    """``qtbot`` as a user's hands, counting the user's actions.

    One action is: a click (a double click counts once: its first click), a key press, a
    typed text (the keys of one word or phrase), opening a list, choosing a file in a file
    dialog, a drag (press, move, release), and going to another field before typing into it (a click into it; a triple
    click when its text is selected to be typed over). Everything else is ``qtbot``'s own.

    Attributes:
        actions: what was done, in order (``len(actions)`` is the count).
    """

    def __init__(self, qtbot: Any) -> None:
        self._bot = qtbot
        self._at: object = None  # the widget the user's hands are on
        self.actions: list[str] = []

    def __getattr__(self, name: str) -> Any:
        return getattr(self._bot, name)

    def count(self, what: str, at: object = None) -> None:
        self.actions.append(what)
        if at is not None:
            self._at = at

    def _go_to(self, widget: object) -> None:
        if widget is not self._at:
            self.count("click into the field", widget)

    def mouseClick(self, widget: Any, *args: Any, **kwargs: Any) -> None:
        self.count("click", widget)
        self._bot.mouseClick(widget, *args, **kwargs)

    def mouseDClick(self, *args: Any, **kwargs: Any) -> None:
        self._bot.mouseDClick(*args, **kwargs)  # the click before it was counted

    def keyClick(self, widget: Any, key: Any, *args: Any, **kwargs: Any) -> None:
        self._go_to(widget)
        self.count(f"key {Qt.Key(key).name}")
        self._bot.keyClick(widget, key, *args, **kwargs)

    def keyClicks(self, widget: Any, text: str, *args: Any, **kwargs: Any) -> None:
        self._go_to(widget)
        self.count(f"type {text!r}")
        self._bot.keyClicks(widget, text, *args, **kwargs)


def _count(qtbot: Any, what: str, at: object = None) -> None:
    """Count an action done without qtbot (opening a list, a file dialog's choice);
    ``at`` is where the user's hands are after it.
    """
    if isinstance(qtbot, CountingBot):
        qtbot.count(what, at)


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
    return _one_added(window, before, key)


def search_insert(qtbot: Any, window: MainWindow, text: str, expect: str) -> str:
    """Type ``text`` into the palette's search field and press Enter (search-to-insert);
    checks that the node added is ``expect`` (an operation id or a kind) and returns its id.
    """
    before = _ids(window)
    field = window.views.palette.search_field
    _replace_text(qtbot, field, text)
    qtbot.keyClick(field, Qt.Key.Key_Return)
    added = _one_added(window, before, text)
    node = window.document.node(added)
    assert expect in _what(node), f"{text!r} inserted {node.op or node.kind}"
    return added


def search_down_insert(qtbot: Any, window: MainWindow, text: str, expect: str) -> str:
    """Type ``text`` into the palette's search field, press Down until the current hit is
    ``expect`` (an operation id, a kind or a library subtree's id), then Enter; the added
    node's id.
    """
    before = _ids(window)
    palette = window.views.palette
    _replace_text(qtbot, palette.search_field, text)
    for _ in range(palette.hits.count()):
        hit = palette.current_hit()
        if hit is not None and expect in (hit.op, hit.kind.value):
            break
        qtbot.keyClick(palette.search_field, Qt.Key.Key_Down)
    qtbot.keyClick(palette.search_field, Qt.Key.Key_Return)
    added = _one_added(window, before, text)
    node = window.document.node(added)
    assert expect in _what(node), f"{text!r} inserted {node.op or node.kind}"
    return added


def _what(node: NodeSpec) -> tuple[str | None, ...]:
    """What a node is, as a palette item names it: its operation, kind or subtree id."""
    return (node.op, node.kind.value, node.subtree.id if node.subtree else None)


def double_click_palette(qtbot: Any, window: MainWindow, key: str) -> str:
    """Clear the search, double-click the palette row of ``key``; the added node's id."""
    before = _ids(window)
    palette = window.views.palette
    _replace_text(qtbot, palette.search_field, "")
    row = palette_row(window, key)
    palette.tree.scrollToItem(row)
    centre = palette.tree.visualItemRect(row).center()
    # A double click is press, release, then a second press that Qt reports as double.
    qtbot.mouseClick(palette.tree.viewport(), Qt.MouseButton.LeftButton, pos=centre)
    qtbot.mouseDClick(palette.tree.viewport(), Qt.MouseButton.LeftButton, pos=centre)
    return _one_added(window, before, key)


def show_tab(qtbot: Any, window: MainWindow, title: str) -> None:
    """Click the dock tab called ``title`` (Palette, Objects, Library...) unless it shows."""
    dock = next(d for d in window.findChildren(QDockWidget) if d.windowTitle() == title)
    if not dock.visibleRegion().isEmpty():
        return
    for bar in window.findChildren(QTabBar):
        index = next((i for i in range(bar.count()) if bar.tabText(i) == title), -1)
        if index >= 0 and bar.isVisible():
            qtbot.mouseClick(bar, Qt.MouseButton.LeftButton, pos=bar.tabRect(index).center())
            qtbot.waitUntil(lambda: not dock.visibleRegion().isEmpty(), timeout=2000)
            return
    raise LookupError(f"no tab {title!r} to click")


def drag_object_onto(qtbot: Any, window: MainWindow, name: str, node_id: str) -> str:
    """Drag the object model ``name`` from the Objects panel onto a node of the canvas (one
    action: press on the model, release on the node); the id of the node it added.
    """
    before = _ids(window)
    objects = window.views.objects
    row = objects.list.item(objects.names().index(name))
    mime = objects.list.mimeData([row])  # what the list hands to a drag
    canvas = window.views.canvas
    canvas.center_on(node_id)
    item = canvas.item(node_id)
    pos = canvas.viewer.mapFromScene(item.mapToScene(item.shape_rect().center()))
    _count(qtbot, f"drag {name} onto the canvas", canvas.viewer)
    event = QDropEvent(
        QPointF(pos), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )  # fmt: skip
    canvas.viewer.dropEvent(event)
    return _one_added(window, before, name)


def select(window: MainWindow, node_id: str, qtbot: Any = None) -> None:
    """Select a node on the canvas (as a click on it would; counted as one when ``qtbot``
    counts and the node was not selected yet).
    """
    if window.views.canvas.selected_ids() != [node_id]:
        _count(qtbot, "click a node")
    window.views.canvas.select(node_id)
    assert window.views.inspector.shown_node_id() == node_id


def click_node(qtbot: Any, window: MainWindow, node_id: str) -> None:
    """Bring a node into view and click its body on the canvas; the inspector then shows it."""
    canvas = window.views.canvas
    canvas.center_on(node_id)
    item = canvas.item(node_id)
    viewer = canvas.viewer
    rect = item.shape_rect()
    # A spot of the body that nothing covers (ports sit on the edges, the title on top).
    spots = [
        QPointF(rect.left() + 16, rect.bottom() - 6),
        QPointF(rect.right() - 16, rect.center().y()),
    ]
    points = [viewer.mapFromScene(item.mapToScene(spot)) for spot in spots]
    pos = next((p for p in points if viewer.items(p)[:1] == [item]), None)
    assert pos is not None, "no free spot of the node to click"
    qtbot.mouseClick(viewer.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert canvas.selected_ids() == [node_id], f"the click selected {canvas.selected_ids()}"
    assert window.views.inspector.shown_node_id() == node_id


def rename(qtbot: Any, window: MainWindow, node_id: str, name: str) -> None:
    select(window, node_id, qtbot)
    field = window.views.inspector.name_field
    _replace_text(qtbot, field, name)
    qtbot.keyClick(field, Qt.Key.Key_Return)


def bind_reference(qtbot: Any, window: MainWindow, node_id: str, port: str, name: str) -> None:
    """Bind a port to a named parameter (inputs: choose "parameter" first; a user leaves
    the name it then shows, the first offered, when it is the one wanted).
    """
    select(window, node_id, qtbot)
    row: PortRow = window.views.inspector.port_row(port)
    if row.mode_combo.count():
        if row.mode == MODE_REFERENCE and row.ref_field.text() == name:
            return  # already bound so (a fresh node's input pre-bound)
        choose_index(qtbot, row.mode_combo, MODE_REFERENCE)
        binding = window.document.node(node_id).params.get(port)
        if row.ref_field.text() == name and binding is not None and binding.ref == name:
            return
    elif row.ref_field.text() == name:
        return  # an output already written there (bound as the plan's other instances)
    _replace_text(qtbot, row.ref_field, name)
    qtbot.keyClick(row.ref_field, Qt.Key.Key_Return)


def set_value(
    qtbot: Any,
    window: MainWindow,
    node_id: str,
    port: str,
    value: Any,
    ptype: ParamType | None = None,
) -> None:
    """Give a port a fixed value: choose "value" (and the type), then enter the value in
    its editor as a user would (type it, or pick it from the combo).
    """
    select(window, node_id, qtbot)
    row: PortRow = window.views.inspector.port_row(port)
    if _bound_to(window, node_id, port, value):
        return  # a user leaves a binding that is already right
    wrong_type = ptype is not None and ptype is not row.value_type
    unset = row.mode == MODE_UNSET and not wrong_type  # its editor shows: enter it there
    if row.mode != MODE_VALUE and not unset:
        choose_index(qtbot, row.mode_combo, MODE_VALUE)
    if wrong_type:
        assert ptype is not None
        choose(qtbot, row.type_combo, ptype.value)
    assert row.editor is not None
    if unset or row.editor.value() != value:  # a user leaves a value that is already right
        _enter(qtbot, row.editor, value)


def _bound_to(window: MainWindow, node_id: str, port: str, value: Any) -> bool:
    """Whether the port already holds ``value`` (an instance's input bound as elsewhere)."""
    binding = window.document.node(node_id).params.get(port)
    return binding is not None and not binding.is_ref and binding.value == value


def unset(qtbot: Any, window: MainWindow, node_id: str, port: str) -> None:
    """Choose "not set" / "default" for a port."""
    select(window, node_id, qtbot)
    choose_index(qtbot, window.views.inspector.port_row(port).mode_combo, MODE_UNSET)


def _enter(qtbot: Any, editor: ParamEditor, value: Any) -> None:
    if isinstance(editor, WaypointEditor):
        choose(qtbot, editor.combo, value.name if isinstance(value, Waypoint) else str(value))
    elif isinstance(editor, ChoiceEditor):
        choose(qtbot, editor.combo, str(value))
    elif isinstance(editor, ObjectModelEditor):
        line = editor.combo.lineEdit()
        _replace_text(qtbot, line, value.name if isinstance(value, ObjectModel) else str(value))
        qtbot.keyClick(line, Qt.Key.Key_Return)
    elif isinstance(editor, TextEditor):
        _replace_text(qtbot, editor.line, str(value))
        qtbot.keyClick(editor.line, Qt.Key.Key_Return)
    elif isinstance(editor, NumberEditor):
        spin = editor.spin
        shown = spin.unit.to_display(float(value))
        spin.selectAll()
        qtbot.keyClicks(spin, f"{shown:.{spin.decimals()}f}")
        qtbot.keyClick(spin, Qt.Key.Key_Return)
    else:  # pose, region, joints grids: no single field to type into
        editor.set_value(value)
        editor.value_committed.emit(value)
    assert editor.value() == value, f"the editor shows {editor.value()!r}, not {value!r}"


def choose(qtbot: Any, combo: QComboBox, text: str) -> None:
    """Choose the entry whose text is ``text`` (or starts with ``text (``) from a combo."""
    texts = [combo.itemText(i) for i in range(combo.count())]
    index = next((i for i, t in enumerate(texts) if t == text or t.startswith(f"{text} (")), -1)
    assert index >= 0, f"the combo offers {texts}, not {text!r}"
    choose_index(qtbot, combo, index)


def choose_index(qtbot: Any, combo: QComboBox, index: int) -> None:
    """Open the combo's list, move to entry ``index`` with the arrow keys, press Enter."""
    _count(qtbot, "open a list", combo.view())
    combo.showPopup()
    view = combo.view()
    qtbot.waitUntil(view.isVisible, timeout=2000)
    current = view.currentIndex().row()
    if current < 0:
        qtbot.keyClick(view, Qt.Key.Key_Home)
        current = view.currentIndex().row()
    key = Qt.Key.Key_Down if index > current else Qt.Key.Key_Up
    for _ in range(abs(index - current)):
        qtbot.keyClick(view, key)
    qtbot.keyClick(view, Qt.Key.Key_Return)
    assert combo.currentIndex() == index, f"the combo shows entry {combo.currentIndex()}"


# ---------------------------------------------------------------------- plan panels


def plan_panels(window: MainWindow) -> tuple[PlanSettingsPanel, WaypointsPanel]:
    """The window's plan settings and waypoints panels; docked here if the window has none
    yet (as the window does it: registry changes reach the waypoints panel).
    """
    settings = window.findChild(PlanSettingsPanel)
    if settings is None:
        settings = PlanSettingsPanel(window.document, window)
        _dock(window, "plan", "Plan", settings)
    waypoints = window.findChild(WaypointsPanel)
    if waypoints is None:
        waypoints = WaypointsPanel(window.document, window.session.registry, window)
        window.session.registry_changed.connect(waypoints.set_registry)
        waypoints.message.connect(window.show_message)
        _dock(window, "waypoints", "Waypoints", waypoints)
    return settings, waypoints


def _dock(window: MainWindow, name: str, title: str, widget: QWidget) -> None:
    dock = QDockWidget(title, window)
    dock.setObjectName(f"{name}_dock")
    dock.setWidget(widget)
    window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
    dock.show()


def set_run_policy(qtbot: Any, window: MainWindow, policy: RunPolicy) -> None:
    choose(qtbot, plan_panels(window)[0].policy_combo, POLICY_TEXT[policy])


def set_plan_name(qtbot: Any, window: MainWindow, name: str) -> None:
    field = plan_panels(window)[0].name_field
    _replace_text(qtbot, field, name)
    qtbot.keyClick(field, Qt.Key.Key_Return)


def import_waypoints(qtbot: Any, window: MainWindow, path: Path) -> None:
    """Press the waypoints panel's Import button and pick ``path`` in the file dialog."""
    panel = plan_panels(window)[1]
    panel.ask_path = lambda parent: str(path)
    qtbot.mouseClick(panel.import_button, Qt.MouseButton.LeftButton)
    _count(qtbot, "choose the file")


# ---------------------------------------------------------------------- runs


def press_run(qtbot: Any, window: MainWindow) -> None:
    """Click the Run button of the toolbar."""
    toolbar = window.findChild(QToolBar, "run_toolbar")
    assert toolbar is not None, "the window has no run toolbar"
    button = toolbar.widgetForAction(window.run_actions.run)
    assert button is not None and button.isEnabled(), "the Run button is not there or disabled"
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)


def run_to_end(qtbot: Any, window: MainWindow, timeout_ms: int = 30_000) -> RunOutcome:
    """Press Run and wait for the run to finish; the outcome."""
    with qtbot.waitSignal(window.controller.run_finished, timeout=timeout_ms) as blocker:
        press_run(qtbot, window)
    return blocker.args[0]


def node_named(window: MainWindow, name: str) -> str:
    return next(n.id for _, n in window.document.plan.walk() if n.name == name)


def _ids(window: MainWindow) -> list[str]:
    return [n.id for _, n in window.document.plan.walk()]


def _one_added(window: MainWindow, before: Iterable[str], what: str) -> str:
    old = set(before)
    added = [i for i in _ids(window) if i not in old]
    assert len(added) == 1, f"inserting {what!r} from the palette added {len(added)} nodes"
    return added[0]


def _replace_text(qtbot: Any, field: Any, text: str) -> None:
    """Select all of a line edit and type over it (an empty ``text`` deletes it)."""
    if field.text():
        _count(qtbot, "select the text", field)
    field.selectAll()
    if text:
        qtbot.keyClicks(field, text)
    else:
        qtbot.keyClick(field, Qt.Key.Key_Backspace)
