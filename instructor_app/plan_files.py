"""PlanFiles: new, open, save, save as and crash recovery of the window's plan.

The window's File menu and start page call these; the questions go through Dialogs, the
recent files into AppSettings, and the window's title follows the document's name and state.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QWidget

from instructor_app.cell_control import ShowMessage
from instructor_app.dialogs import APP_TITLE, DISCARD, SAVE, Dialogs
from instructor_app.document.autosave import Autosaver, offer_recoveries
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.settings import AppSettings, is_shipped_example

UNNAMED = ("", "Untitled plan")  # the names of a plan the user never named


def plan_name_of(path: Path) -> str:
    """The plan name a file suggests: ``pick cups.costar.json`` -> "pick cups"."""
    name = path.name
    for suffix in (".costar.json", ".json"):
        if name.endswith(suffix):
            return name[: -len(suffix)] or name
    return name


class PlanFiles(QObject):
    """The plan's file operations.

    Args:
        document: the plan being edited.
        autosaver: where a crashed session's plans are found.
        dialogs: file choosers and questions.
        settings: the last folder and the recent files.
        show_message: the window's status-bar message.
        show_canvas: called when a new plan replaces the start page.
        window: the parent of the dialogs; its title names the plan.
    """

    def __init__(
        self,
        document: PlanDocument,
        autosaver: Autosaver,
        dialogs: Dialogs,
        settings: AppSettings,
        show_message: ShowMessage,
        show_canvas: Callable[[], None],
        window: QWidget,
    ) -> None:
        super().__init__(window)
        self.document, self.autosaver, self.dialogs = document, autosaver, dialogs
        self.settings, self.show_message, self.window = settings, show_message, window
        self._show_canvas = show_canvas

    def display_name(self) -> str:
        path = self.document.path
        return path.name if path is not None else (self.document.plan.name or "Untitled plan")

    def update_title(self) -> None:
        marker = "*" if self.document.dirty else ""
        self.window.setWindowTitle(f"{self.display_name()}{marker} — {APP_TITLE}")

    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False when the user cancelled (or saving failed)."""
        if not self.document.dirty:
            return True
        answer = self.dialogs.ask_save_changes(self.window, self.display_name())
        if answer == SAVE:
            return self.save_plan()
        return answer == DISCARD

    def new_plan(self) -> None:
        if self.maybe_save():
            self.document.new()
            self._show_canvas()

    def open_plan(self, path: str | Path | None = None) -> bool:
        """Open a plan (asks for the file when ``path`` is None); False when not opened."""
        if not self.maybe_save():
            return False
        if path is None:
            path = self.dialogs.open_path(self.window, self.settings.last_dir())
            if not path:
                return False
        return self._open_or_save(self.document.open, path, "Cannot open the plan", "Opened")

    def save_plan(self) -> bool:
        """Save to the plan's file; asks for a new one (Save As) when it has none or when
        it is a shipped example, which stays as shipped (also after a crash recovery).
        """
        path = self.document.path
        if path is None or is_shipped_example(path):
            return self.save_plan_as()
        return self._save_to(path)

    def save_plan_as(self) -> bool:
        last = self.settings.last_dir()
        folder = Path(last) if last and not is_shipped_example(Path(last) / "x") else Path.home()
        chosen = self.dialogs.save_path(self.window, str(folder / f"{self.display_name()}"))
        if not chosen:
            return False
        path = Path(chosen)
        if not path.name.endswith(".json"):
            path = path.with_name(path.name + ".costar.json")
        named = self.document.plan.name not in UNNAMED
        if not named:  # a plan the user never named takes the file's name (one undo step)
            self.document.rename_plan(plan_name_of(path))
        if self._save_to(path):
            return True
        if not named:
            self.document.undo_stack.undo()
        return False

    def _save_to(self, path: Path) -> bool:
        return self._open_or_save(self.document.save, path, "Cannot save the plan", "Saved")

    def _open_or_save(
        self, action: Callable[[str | Path], object], path: str | Path, failed: str, done: str
    ) -> bool:
        """Open or save the plan by ``action(path)``: the file joins the recent ones and the
        status bar says ``done``, or a DocumentError is shown under the title ``failed``.
        """
        try:
            action(path)
        except DocumentError as exc:
            self.dialogs.error(self.window, failed, str(exc))
            return False
        self.settings.add_recent(path)
        self.show_message(f"{done} {path}")
        return True

    def offer_recoveries(self) -> bool:
        """Offer the plans a crashed session left (newest first); True when one was restored.
        Declined ones are deleted.
        """
        restored = offer_recoveries(
            self.document,
            self.autosaver,
            lambda text: self.dialogs.ask_restore(self.window, text),
            lambda text: self.dialogs.error(self.window, "Cannot restore the plan", text),
        )
        if restored is not None:
            self.show_message(f"Restored {restored.describe()}")
        return restored is not None
