"""The subtree library in the main window: its panel, its menu, palette entries, canvas drops.

:class:`LibraryController` owns the :class:`engine.library.Library` (the folder chosen by
``--library``, ``$COSTAR_LIBRARY`` or the setting, else the user's, plus the shipped one) and
turns the panel's and menu's requests into document edits
(:class:`instructor_app.document.subtree_edits.SubtreeEditor`, each an undo step) and library
saves. Nothing here draws: the panel and the canvas show what the document holds.

A library save runs on a worker thread (it may wait for another Instructor's lock, or for a
slow network folder) and comes back through a queued signal; the GUI thread only builds the
subtree before and puts the instance in after.
"""

from __future__ import annotations

import contextlib
import copy
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QDialog, QFileDialog, QMenu, QWidget

from engine.library import Library, LibraryEntry, LibraryError
from engine.spec import Binding, NodeKind, NodeSpec, SubtreeSpec
from engine.subtree_ops import Usage, find_usages, ports_of
from engine.types import ObjectModel, ParamType
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.document.subtree_edits import SubtreeEditor
from instructor_app.node_factory import PaletteItem
from instructor_app.subtree_dialog import SaveSubtreeDialog, SubtreeChoices

__all__ = ["LibraryController", "library_palette_items"]

InsertionPoint = Callable[[], "tuple[str | None, int | None]"]


def library_palette_items(library: Library) -> list[PaletteItem]:
    """One palette entry per library subtree (search finds them; Enter inserts an instance)."""
    return [
        PaletteItem(
            NodeKind.SUBTREE, e.subtree.id, e.subtree.name, e.subtree.description, "library"
        )
        for e in sorted(library.entries, key=lambda e: e.subtree.name)
    ]


@dataclass(frozen=True)
class _PendingSave:
    """A save on its way: the node it replaces, as it was when the save began."""

    node_id: str
    node: NodeSpec
    choices: SubtreeChoices


class LibraryController(QObject):
    """The library's panel, menu and edits in one window.

    Args:
        document: the plan edited.
        views: the window's views (canvas, palette, validation, library panel).
        registry: a callable giving the cell's operations now.
        insertion_point: where a new node goes, from the canvas selection.
        root: the writable library folder.
        parent: the window (dialogs are its children).

    Signals:
        message(str): something to show in the status bar.
        save_finished(object): a save asked by :meth:`save_as_subtree` is over: the saved
            SubtreeSpec, or None when it failed (the message says why).
    """

    message = Signal(str)
    save_finished = Signal(object)
    _saved = Signal(object, object)  # from the saving thread: (_PendingSave, spec or why not)

    def __init__(
        self,
        document: PlanDocument,
        views: Any,
        registry: Callable[[], Any],
        insertion_point: InsertionPoint,
        root: Path,
        parent: QWidget,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.views = views
        self.registry = registry
        self.insertion_point = insertion_point
        self.window = parent
        self.editor = SubtreeEditor(document)
        self.library = Library(root)
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="costar-library-save")
        self._saving = False
        self._saved.connect(self._on_saved)
        self.dialog_factory: Callable[..., SaveSubtreeDialog] = SaveSubtreeDialog
        self.folder_chooser: Callable[[], str] = lambda: QFileDialog.getExistingDirectory(
            parent, "Find usages in the plans of this folder"
        )
        self.last_usages: list[Usage] = []
        panel = views.library
        panel.insert_requested.connect(lambda entry: self.insert(entry.subtree.id))
        panel.usages_requested.connect(lambda entry: self.find_usages(entry))
        panel.reload_requested.connect(self.reload)
        views.canvas.instance_inserter = self._insert_under
        views.canvas.selection_changed.connect(self._show_inside)
        self.actions = self._make_actions()
        self.reload()

    # ------------------------------------------------------------------ library

    def reload(self) -> None:
        """Read the library folders again and show what they hold."""
        self.library.scan()
        self.views.library.set_library(self.library)
        self.views.palette.set_extra_items(library_palette_items(self.library))
        self.views.validation.set_library(self.library)
        if self.library.problems:
            self.message.emit(f"{len(self.library.problems)} library file(s) skipped")

    def subtree(self, subtree_id: str) -> SubtreeSpec:
        entry = self.library.entry(subtree_id)
        if entry is None:
            raise DocumentError(f"the library has no subtree {subtree_id!r}")
        return entry.subtree

    # ------------------------------------------------------------------ edits

    def insert(self, subtree_id: str) -> str | None:
        """An instance where the selection says (as "Add" of the palette does)."""
        try:
            parent_id, index = self.insertion_point()
            node_id = self.editor.insert_instance(self.subtree(subtree_id), parent_id, index)
        except DocumentError as exc:
            self.message.emit(f"Cannot insert the subtree here: {exc}")
            return None
        self.views.canvas.select(node_id)
        return node_id

    def _insert_under(
        self, subtree_id: str, parent_id: str | None, object_name: str | None = None
    ) -> str:
        """An instance dropped on the canvas; an object model dropped with it (dragged from
        the Objects panel) is given to its first object input, and names it ("Pick cup").
        """
        subtree = self.subtree(subtree_id)
        params: dict[str, Binding] = {}
        if object_name:
            port = next((p for p in subtree.inputs if p.type is ParamType.OBJECT), None)
            if port is None:
                raise DocumentError(f"{subtree.name} takes no object")
            params[port.name] = Binding.fixed(ObjectModel(object_name), ParamType.OBJECT)
        return self.editor.insert_instance(subtree, parent_id, params=params)

    def save_as_subtree(self, node_id: str, choices: SubtreeChoices) -> bool:
        """Save a node and those below it to the library, off the GUI thread; once saved, an
        instance takes their place and ``save_finished`` says so. False (and a message) when
        the save is refused at once (a bad port, a save already under way).
        """
        if self._saving:
            self.message.emit("Cannot save the subtree: another save is under way; try again")
            return False
        try:
            made = self.editor.save_as_subtree(
                node_id,
                choices.name,
                self.registry(),
                choices.open_ports,
                choices.outputs,
                choices.description,
            )
            pending = _PendingSave(node_id, copy.deepcopy(self.document.node(node_id)), choices)
        except DocumentError as exc:
            self.message.emit(f"Cannot save the subtree: {exc}")
            return False
        self._saving = True
        self.actions["save_subtree"].setEnabled(False)
        self.message.emit(f"Saving {made.name} to the library…")
        self._pool.submit(self._save, made, pending)
        return True

    @property
    def saving(self) -> bool:
        """True while a library save runs."""
        return self._saving

    def _save(self, made: SubtreeSpec, pending: _PendingSave) -> None:
        """On the worker thread: the library save only (no document, no widget)."""
        try:
            outcome: object = self.library.save(made, pending.choices.folder)
        except LibraryError as exc:
            outcome = f"Cannot save the subtree: {exc}"
        except Exception as exc:  # an unexpected failure must still end the save in the GUI
            outcome = f"Cannot save the subtree: {type(exc).__name__}: {exc}"
        with contextlib.suppress(RuntimeError):  # the window is gone
            self._saved.emit(pending, outcome)

    def _on_saved(self, pending: object, outcome: object) -> None:
        assert isinstance(pending, _PendingSave)
        self._saving = False
        self.actions["save_subtree"].setEnabled(True)
        if not isinstance(outcome, SubtreeSpec):
            self.message.emit(str(outcome))
            self.save_finished.emit(None)
            return
        try:
            unchanged = self.document.node(pending.node_id) == pending.node
        except DocumentError:  # deleted, or another plan opened
            unchanged = False
        if unchanged:
            self.editor.use_saved(pending.node_id, outcome, pending.choices.open_ports)
        self.reload()
        if unchanged:
            self.message.emit(f"Saved {outcome.name} (version {outcome.version}) to the library")
        else:
            self.message.emit(
                f"Saved {outcome.name} (version {outcome.version}) to the library; the nodes "
                "changed meanwhile, so they were left as they are"
            )
        self.save_finished.emit(outcome)

    def shutdown(self) -> None:
        """Let a save under way finish on its thread (its file is written whole or not at
        all); nothing new starts.
        """
        self._pool.shutdown(wait=False, cancel_futures=True)

    def detach(self, node_id: str) -> str | None:
        try:
            return self.editor.detach(node_id)
        except DocumentError as exc:
            self.message.emit(f"Cannot detach: {exc}")
            return None

    def update(self, node_id: str) -> bool:
        """Move an instance to the library's newest version of its subtree."""
        node = self.document.node(node_id)
        newer = self.library.latest(node.subtree.id) if node.subtree else None
        if newer is None or node.subtree is None or newer.version <= node.subtree.version:
            self.message.emit(f"{node.label} already runs the library's newest version")
            return False
        self.editor.update(node_id, newer)
        return True

    def find_usages(self, entry: LibraryEntry, folder: str | None = None) -> list[Usage]:
        """The plans of a folder that use a subtree; shown in the library panel."""
        chosen = folder if folder is not None else self.folder_chooser()
        if not chosen:
            return []
        usages, problems = find_usages(Path(chosen), entry.subtree.id)
        self.last_usages = usages
        self.views.library.show_usages(entry.subtree.name, usages, problems)
        return usages

    def _show_inside(self, node_ids: list[str]) -> None:
        """Open the selected instance in the Inside panel (statuses of runs shown live)."""
        plan = self.document.plan
        node = plan.find(node_ids[0]) if len(node_ids) == 1 else None
        if node is not None and node.kind is NodeKind.SUBTREE:
            self.views.inside.show_instance(plan, node)

    # ------------------------------------------------------------------ menu

    def _make_actions(self) -> dict[str, QAction]:
        actions = {
            "save_subtree": QAction("Save selection as &subtree…", self.window),
            "detach": QAction("&Detach instance into nodes", self.window),
            "update": QAction("&Update instance to the library's version", self.window),
            "reload": QAction("&Reload library", self.window),
        }
        actions["save_subtree"].triggered.connect(self._ask_save)
        actions["detach"].triggered.connect(lambda: self._on_selected(self.detach))
        actions["update"].triggered.connect(lambda: self._on_selected(self.update))
        actions["reload"].triggered.connect(self.reload)
        return actions

    def fill_menu(self, menu: QMenu) -> None:
        menu.addActions(list(self.actions.values()))

    def _selected(self) -> str | None:
        selected = self.views.canvas.selected_ids()
        if len(selected) != 1:
            self.message.emit("Select one node first")
            return None
        return str(selected[0])

    def _on_selected(self, edit: Callable[[str], object]) -> None:
        node_id = self._selected()
        if node_id is not None:
            edit(node_id)

    def _ask_save(self) -> None:
        node_id = self._selected()
        if node_id is None:
            return
        dialog = self.dialog_factory(
            self.document.node(node_id), ports_of(self.document.plan, self.registry()), self.window
        )
        if dialog.exec() == QDialog.DialogCode.Accepted:
            self.save_as_subtree(node_id, dialog.choices())
