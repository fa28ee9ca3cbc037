"""The subtree library in the Instructor, driven through its widgets.

Save a selection as a subtree (the dialog's tables), the Library panel (folders, search,
preview, insert, find usages), palette search-to-insert of a library subtree, an instance's
binding form in the inspector (and its name following its object), detach and update, the
shipped Pick taken by dragging an object model onto the canvas, each one undo step. A library save runs off
the GUI thread: a lock held elsewhere does not stop the window.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QPointF, Qt, QTimer
from PySide6.QtGui import QDropEvent
from PySide6.QtWidgets import QDialog

from engine.files import dump_plan
from engine.library import LIBRARY_ENV, Library
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ObjectModel, ParamType
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from instructor_app.subtree_dialog import SaveSubtreeDialog
from tests.instructor_app.gui_driver import (
    ScriptedDialogs,
    bind_reference,
    make_window,
    rename,
    run_to_end,
    search_insert,
    select,
    set_value,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


@pytest.fixture
def window(qtbot: Any, none_session: CellSession, tmp_path: Path) -> MainWindow:
    return make_window(qtbot, none_session, tmp_path, ScriptedDialogs())


def _op(label: str, op: str, **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, label, op=op, params=params)


def _text(value: str) -> Binding:
    return Binding.fixed(value, ParamType.TEXT)


def _plan() -> PlanSpec:
    part = NodeSpec(
        NodeKind.SEQUENCE, "part",
        children=[_op("say", "debug.log", message=_text("hello")),
                  _op("keep", "debug.set_param", value=_text("x"), name=Binding.reference("OUT"))],
    )  # fmt: skip
    check = _op("check", "debug.check_param", value=Binding.reference("OUT"), expected=_text("x"))
    return PlanSpec(NodeSpec(NodeKind.SEQUENCE, "main", children=[part, check]), "library test")


def _open(window: MainWindow, tmp_path: Path, plan: PlanSpec) -> None:
    path = tmp_path / "plan.costar.json"
    path.write_text(dump_plan(plan), encoding="utf-8")
    assert window.open_plan(path)


def _node(window: MainWindow, name: str) -> NodeSpec:
    return next(n for _, n in window.document.plan.walk() if n.name == name)


def _save_part_with_open_message(qtbot: Any, window: MainWindow) -> str:
    """Select "part", open Save as subtree, tick its message as the input MESSAGE and OUT as
    an output, save; returns the instance's id once the save is over.
    """
    with qtbot.waitSignal(window.library.save_finished, timeout=20000) as finished:
        _ask_to_save_part(window)
    assert finished.args[0] is not None, "the save failed"
    return _node(window, "part").id


def _ask_to_save_part(window: MainWindow, folder: str = "tests") -> None:
    """Select "part" and save it as a subtree (MESSAGE open, OUT an output) in ``folder``; the
    save runs on.
    """
    shown: list[SaveSubtreeDialog] = []

    def dialog(*args: Any) -> SaveSubtreeDialog:
        made = SaveSubtreeDialog(*args)
        row = made.parameter_rows().index("say / message")
        made.set_open(row, "MESSAGE", "what to say")
        made.set_output(made.output_rows().index("OUT"), "the kept value")
        made.folder_field.setText(folder)
        made.exec = lambda: QDialog.DialogCode.Accepted  # type: ignore[method-assign]
        shown.append(made)
        return made

    window.library.dialog_factory = dialog
    select(window, _node(window, "part").id)
    window.library.actions["save_subtree"].trigger()
    assert shown, "the dialog was not shown"


def test_save_selection_as_subtree_runs_undoes_and_detaches(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    before = window.document.serialized()
    instance_id = _save_part_with_open_message(qtbot, window)
    instance = window.document.node(instance_id)
    assert instance.kind is NodeKind.SUBTREE
    assert instance.params["MESSAGE"] == _text("hello")
    saved = Path(os.environ[LIBRARY_ENV]) / "tests" / "part.subtree.json"
    assert saved.exists()
    assert "part" in window.views.library.visible_names()
    outcome = run_to_end(qtbot, window)
    assert outcome.status is Status.SUCCESS
    # one undo step puts the plain nodes back, byte for byte
    window.document.undo_stack.undo()
    assert window.document.serialized() == before
    window.document.undo_stack.redo()
    with_instance, label = window.document.serialized(), window.document.node(instance_id).label
    select(window, instance_id)
    window.library.actions["detach"].trigger()
    assert window.document.undo_stack.undoText() == f"Detach {label}"  # one step, its children:
    window.document.undo_stack.undo()  # the nodes back, and the definition they dropped
    assert window.document.serialized() == with_instance
    window.document.undo_stack.redo()
    part = _node(window, "part")
    assert part.kind is NodeKind.SEQUENCE and part.children[0].params["message"] == _text("hello")
    assert window.document.plan.subtrees == []
    assert run_to_end(qtbot, window).status is Status.SUCCESS


def test_an_instance_input_is_bound_through_its_port_row(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    instance_id = _save_part_with_open_message(qtbot, window)
    set_value(qtbot, window, instance_id, "MESSAGE", "good bye")
    assert window.document.node(instance_id).params["MESSAGE"] == _text("good bye")
    assert window.views.inspector.port_row("OUT") is not None  # outputs are ports too
    window.document.undo_stack.undo()
    assert window.document.node(instance_id).params["MESSAGE"] == _text("hello")


def test_library_panel_lists_folders_searches_and_previews(qtbot: Any, window: MainWindow) -> None:
    panel = window.views.library
    assert {"Handoff", "Unholster", "Transfer", "Holster", "Return"} <= set(panel.visible_names())
    qtbot.keyClicks(panel.search_field, "suction")
    assert set(panel.visible_names()) == {"Unholster", "Holster"}
    panel.search_field.clear()
    panel.select("Transfer")
    text = panel.preview.toPlainText()
    assert "Version 1" in text and "OBJECT: ObjectModel" in text and "Shape" in text
    assert "perception.detect_objects" in text


def test_palette_search_inserts_a_library_subtree_with_one_undo(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    before = window.document.serialized()
    select(window, _node(window, "main").id)
    added = search_insert(qtbot, window, "Transfer", "subtree")
    node = window.document.node(added)
    assert node.subtree is not None and node.subtree.id == "kitting.transfer"
    assert [s.name for s in window.document.plan.subtrees] == ["Transfer"]
    select(window, added)
    assert window.views.inspector.kind_label.text().startswith("<b>Subtree Transfer")
    window.document.undo_stack.undo()
    assert window.document.serialized() == before


def test_library_panel_insert_button_and_find_usages(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    panel = window.views.library
    panel.select("Holster")
    select(window, _node(window, "main").id)
    qtbot.mouseClick(panel.insert_button, Qt.MouseButton.LeftButton)
    assert window.document.plan.tree.children[-1].name == "Holster"  # type: ignore[union-attr]
    window.library.folder_chooser = lambda: str(EXAMPLES)
    panel.select("Transfer")
    qtbot.mouseClick(panel.usages_button, Qt.MouseButton.LeftButton)
    assert len(window.library.last_usages) == 3
    assert "kitting.costar.json" in panel.preview.toPlainText()


def test_a_newer_library_version_is_shown_and_the_instance_updates(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    instance_id = _save_part_with_open_message(qtbot, window)
    library = Library(Path(os.environ[LIBRARY_ENV])).scan()  # a second Instructor saves v2
    current = library.latest(window.document.node(instance_id).subtree.id)  # type: ignore[union-attr]
    assert current is not None
    current.description = "says something, keeps a value"
    library.save(current, base_version=current.version)
    window.library.reload()
    problems = window.views.validation.problems()
    assert any("newer version" in p.message and p.node_id == instance_id for p in problems)
    select(window, instance_id)
    before, label = window.document.serialized(), window.document.node(instance_id).label
    window.library.actions["update"].trigger()
    assert window.document.node(instance_id).subtree.version == 2  # type: ignore[union-attr]
    stack = window.document.undo_stack
    assert stack.undoText() == f"Update {label} to version 2"
    after = window.document.serialized()
    stack.undo()
    assert window.document.serialized() == before
    stack.redo()
    assert window.document.serialized() == after
    qtbot.waitUntil(
        lambda: not any("newer version" in p.message for p in window.views.validation.problems())
    )


def test_the_inside_of_a_selected_instance_shows_the_run_live(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    instance_id = _save_part_with_open_message(qtbot, window)
    select(window, instance_id)
    inside = window.views.inside
    assert inside.title.text().startswith("Inside part")
    assert set(inside.status_texts()) == {
        "part (sequence)",
        "say (debug.log)",
        "keep (debug.set_param)",
    }
    assert run_to_end(qtbot, window).status is Status.SUCCESS
    qtbot.waitUntil(lambda: set(inside.status_texts().values()) == {"SUCCESS"})


def test_a_subtree_dragged_from_the_library_onto_a_node_becomes_its_child(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    panel = window.views.library
    panel.select("Unholster")
    row = panel.tree.currentItem()
    mime = panel.tree.mimeData([row])  # what the tree hands to a drag
    canvas = window.views.canvas
    main = canvas.item(_node(window, "main").id)
    pos = canvas.viewer.mapFromScene(main.mapToScene(main.shape_rect().center()))
    event = QDropEvent(
        QPointF(pos), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )  # fmt: skip
    canvas.viewer.dropEvent(event)
    added = window.document.plan.tree.children[-1]  # type: ignore[union-attr]
    assert added.kind is NodeKind.SUBTREE and added.name == "Unholster"
    assert [s.name for s in window.document.plan.subtrees] == ["Unholster"]


def _messages(window: MainWindow) -> list[str]:
    said: list[str] = []
    window.library.message.connect(said.append)
    return said


def _hold_lock_elsewhere(folder: Path, name: str) -> Path:
    """A live lock of another Instructor, on another host: a save waits for it."""
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / f".{name}.lock"
    owner = {"pid": 1, "host": "another-host.invalid", "started": 0}
    lock.write_text(json.dumps(owner), encoding="utf-8")
    return lock


def test_a_save_waiting_for_a_lock_does_not_block_the_window(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    library = Path(os.environ[LIBRARY_ENV])
    lock = _hold_lock_elsewhere(library / "tests", "part.subtree.json")
    window.library.library.lock_wait = 120.0  # it waits as long as the test holds the lock
    _ask_to_save_part(window)  # returns while the save waits for the lock
    assert window.library.saving and lock.exists()
    assert not window.library.actions["save_subtree"].isEnabled()
    ticked: list[bool] = []
    QTimer.singleShot(0, lambda: ticked.append(True))
    qtbot.waitUntil(lambda: ticked == [True])  # the window's event loop runs meanwhile
    assert window.library.saving and _node(window, "part").kind is NodeKind.SEQUENCE
    with qtbot.waitSignal(window.library.save_finished, timeout=20000) as finished:
        lock.unlink()  # the other Instructor is done
    assert finished.args[0] is not None and finished.args[0].name == "part"
    assert (library / "tests" / "part.subtree.json").exists()
    assert _node(window, "part").kind is NodeKind.SUBTREE
    assert window.library.actions["save_subtree"].isEnabled() and not window.library.saving


def test_nodes_changed_while_saving_are_left_as_they_are(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    lock = _hold_lock_elsewhere(Path(os.environ[LIBRARY_ENV]) / "tests", "part.subtree.json")
    window.library.library.lock_wait = 120.0
    said = _messages(window)
    _ask_to_save_part(window)
    set_value(qtbot, window, _node(window, "say").id, "message", "changed meanwhile")
    with qtbot.waitSignal(window.library.save_finished, timeout=20000):
        lock.unlink()
    assert _node(window, "part").kind is NodeKind.SEQUENCE
    assert _node(window, "say").params["message"] == _text("changed meanwhile")
    assert "left as they are" in said[-1]


@pytest.mark.parametrize("folder", ["/tmp/outside", "C:\\x", "a/../../b", "a\x00b"])
def test_a_folder_outside_the_library_is_refused_in_the_window(
    qtbot: Any, window: MainWindow, tmp_path: Path, folder: str
) -> None:
    _open(window, tmp_path, _plan())
    said = _messages(window)
    with qtbot.waitSignal(window.library.save_finished, timeout=20000) as finished:
        _ask_to_save_part(window, folder)
    assert finished.args[0] is None
    assert (
        "Cannot save the subtree" in said[-1] and "expected a folder inside the library" in said[-1]
    )
    assert _node(window, "part").kind is NodeKind.SEQUENCE
    assert not list(Path(os.environ[LIBRARY_ENV]).rglob("*.subtree.json"))


def test_a_saved_selection_is_an_instance_named_by_its_subtree_and_logs_name_its_nodes(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    say = _op("say", "debug.log", message=_text("hello"))
    group = NodeSpec(NodeKind.SEQUENCE, "Sequence", children=[say])  # as the palette names it
    _open(window, tmp_path, PlanSpec(NodeSpec(NodeKind.SEQUENCE, "main", children=[group]), "p"))

    def dialog(*args: Any) -> SaveSubtreeDialog:
        made = SaveSubtreeDialog(*args)
        made.name_field.setText("greet")
        made.folder_field.setText("tests")
        made.exec = lambda: QDialog.DialogCode.Accepted  # type: ignore[method-assign]
        return made

    window.library.dialog_factory = dialog
    select(window, group.id)
    with qtbot.waitSignal(window.library.save_finished, timeout=20000) as finished:
        window.library.actions["save_subtree"].trigger()
    assert finished.args[0] is not None, "the save failed"
    instance = window.document.plan.tree.children[0]  # type: ignore[union-attr]
    assert instance.kind is NodeKind.SUBTREE and instance.label == "greet"
    assert window.views.canvas.mirror.nodes[instance.id].item.look.title == "greet"
    assert run_to_end(qtbot, window).status is Status.SUCCESS
    said = [line for line in window.views.log.lines() if line.endswith("hello")]
    assert said and all("greet" in line and "say" in line for line in said), said
    assert not any(instance.id in line for line in window.views.log.lines())


# ---------------------------------------------------------------------- pick and place (issue 26)


def _drop_on(window: MainWindow, node_id: str, mime: Any) -> None:
    canvas = window.views.canvas
    item = canvas.item(node_id)
    pos = canvas.viewer.mapFromScene(item.mapToScene(item.shape_rect().center()))
    event = QDropEvent(
        QPointF(pos), Qt.DropAction.CopyAction, mime, Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
    )  # fmt: skip
    canvas.viewer.dropEvent(event)


def test_the_shipped_pick_and_place_are_in_the_library_and_the_palette(
    qtbot: Any, window: MainWindow
) -> None:
    panel = window.views.library
    assert {"Pick", "Place"} <= set(panel.visible_names())
    panel.select("Pick")
    text = panel.preview.toPlainText()
    assert "OBJECT: ObjectModel" in text and "gripper.grasp" in text
    qtbot.keyClicks(window.views.palette.search_field, "place")
    hit = window.views.palette.current_hit()
    assert hit is not None and hit.op == "pick_place.place"


def test_an_instance_is_named_after_its_object_until_renamed_one_undo_step_each(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    select(window, _node(window, "main").id)
    pick = search_insert(qtbot, window, "pick", "pick_place.pick")
    document = window.document
    assert document.node(pick).name == "Pick"
    before = document.serialized()
    set_value(qtbot, window, pick, "OBJECT", ObjectModel("cup"))
    assert document.node(pick).name == "Pick cup"
    assert window.views.inspector.name_field.text() == "Pick cup"
    set_value(qtbot, window, pick, "OBJECT", ObjectModel("waste_bin"))
    assert document.node(pick).name == "Pick waste_bin"
    document.undo_stack.undo()
    assert document.node(pick).name == "Pick cup"
    document.undo_stack.undo()
    assert document.serialized() == before
    document.undo_stack.redo()
    rename(qtbot, window, pick, "take the cup")  # a name given by hand stays
    set_value(qtbot, window, pick, "OBJECT", ObjectModel("waste_bin"))
    assert document.node(pick).name == "take the cup"


def test_an_object_dragged_from_the_objects_panel_onto_a_node_is_a_pick_of_it(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    before = window.document.serialized()
    objects = window.views.objects
    row = objects.list.item(objects.names().index("cup"))
    assert row.flags() & Qt.ItemFlag.ItemIsDragEnabled
    _drop_on(window, _node(window, "main").id, objects.list.mimeData([row]))
    added = window.document.plan.tree.children[-1]  # type: ignore[union-attr]
    assert added.kind is NodeKind.SUBTREE and added.subtree is not None
    assert added.subtree.id == "pick_place.pick" and added.name == "Pick cup"
    assert added.params["OBJECT"] == Binding.fixed(ObjectModel("cup"), ParamType.OBJECT)
    assert window.views.canvas.selected_ids() == [added.id]
    assert window.views.inspector.port_row("OBJECT").editor.combo.currentText() == "cup"
    window.document.undo_stack.undo()  # one step
    assert window.document.serialized() == before


def test_an_instance_inserted_is_bound_as_the_plans_other_instances_are(
    qtbot: Any, window: MainWindow, tmp_path: Path
) -> None:
    _open(window, tmp_path, _plan())
    document = window.document
    select(window, _node(window, "main").id)
    first = search_insert(qtbot, window, "ReRegisterRack", "subtree")
    bind_reference(qtbot, window, first, "RACK_POSE", "RACK_POSE")  # an output
    pick = search_insert(qtbot, window, "pick", "pick_place.pick")
    set_value(qtbot, window, pick, "OBJECT", ObjectModel("cup"))
    select(window, _node(window, "main").id)
    before = document.serialized()
    again = search_insert(qtbot, window, "pick", "pick_place.pick")
    cup = Binding.fixed(ObjectModel("cup"), ParamType.OBJECT)
    assert document.node(again).params["OBJECT"] == cup  # as the other Pick: cup
    assert document.node(again).name == "Pick cup"
    assert window.views.inspector.port_row("OBJECT").editor.combo.currentText() == "cup"
    document.undo_stack.undo()  # one step
    assert document.serialized() == before
    select(window, _node(window, "main").id)
    find = search_insert(qtbot, window, "ReRegisterRack", "subtree")
    assert document.node(find).params["RACK_POSE"] == Binding.reference("RACK_POSE")
    assert window.views.inspector.port_row("RACK_POSE").ref_field.text() == "RACK_POSE"
