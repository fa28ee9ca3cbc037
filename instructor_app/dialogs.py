"""The main window's questions and messages, replaceable in tests and headless runs."""

from __future__ import annotations

from PySide6.QtWidgets import QFileDialog, QInputDialog, QMessageBox, QWidget

__all__ = [
    "APP_TITLE",
    "CANCEL",
    "CELL_FILTER",
    "DISCARD",
    "PLAN_FILTER",
    "RECORD_FILTER",
    "SAVE",
    "XML_FILTER",
    "Dialogs",
]

APP_TITLE = "CoSTAR Instructor"
PLAN_FILTER = "CoSTAR plans (*.costar.json);;JSON files (*.json);;All files (*)"
CELL_FILTER = "CoSTAR cells (*.cell.json);;JSON files (*.json);;All files (*)"
XML_FILTER = "BehaviorTree.CPP XML (*.xml);;All files (*)"
RECORD_FILTER = "Run records (*.trace.jsonl);;All files (*)"
SAVE, DISCARD, CANCEL = "save", "discard", "cancel"


def _yes(
    parent: QWidget,
    question: str,
    no: QMessageBox.StandardButton,
    default: QMessageBox.StandardButton,
) -> bool:
    """Ask a question answered by Yes or by ``no`` (No, Cancel); True on Yes."""
    answer = QMessageBox.question(
        parent, APP_TITLE, question, QMessageBox.StandardButton.Yes | no, default
    )
    return answer == QMessageBox.StandardButton.Yes


class Dialogs:
    """The window's questions and messages. Tests replace it, or patch :meth:`make_box`."""

    def make_box(self, parent: QWidget) -> QMessageBox:
        return QMessageBox(parent)

    def ask_save_changes(self, parent: QWidget, name: str) -> str:
        """Ask whether to save the changes: "save", "discard" or "cancel"."""
        box = self.make_box(parent)
        box.setIcon(QMessageBox.Icon.Warning)
        box.setWindowTitle(APP_TITLE)
        box.setText(f"Save the changes to {name}?")
        box.setInformativeText("Your changes are lost if you don't save them.")
        buttons = QMessageBox.StandardButton
        box.setStandardButtons(buttons.Save | buttons.Discard | buttons.Cancel)
        box.setDefaultButton(buttons.Save)
        answer = box.exec()
        return {buttons.Save: SAVE, buttons.Discard: DISCARD}.get(buttons(answer), CANCEL)

    def ask_restore(self, parent: QWidget, description: str) -> bool:
        buttons = QMessageBox.StandardButton
        return _yes(
            parent,
            f"The Instructor did not close properly. Restore the unsaved plan?\n\n{description}",
            no=buttons.No,
            default=buttons.Yes,
        )

    def ask_overwrite_waypoint(self, parent: QWidget, name: str, users: list[str]) -> bool:
        """Ask whether to teach again the waypoint ``name`` that the nodes ``users`` use too."""
        buttons = QMessageBox.StandardButton
        shown = ", ".join(repr(u) for u in users[:5]) + (" ..." if len(users) > 5 else "")
        return _yes(
            parent,
            f"The waypoint {name!r} is also used by {shown}. Teach it again for all of them?",
            no=buttons.Cancel,
            default=buttons.Cancel,
        )

    def error(self, parent: QWidget, title: str, text: str) -> None:
        QMessageBox.critical(parent, title, text)

    def open_path(self, parent: QWidget, folder: str) -> str:
        return QFileDialog.getOpenFileName(parent, "Open plan", folder, PLAN_FILTER)[0]

    def record_open_path(self, parent: QWidget, folder: str) -> str:
        return QFileDialog.getOpenFileName(parent, "Open run record", folder, RECORD_FILTER)[0]

    def open_cell_path(self, parent: QWidget, folder: str) -> str:
        return QFileDialog.getOpenFileName(parent, "Open cell file", folder, CELL_FILTER)[0]

    def save_path(self, parent: QWidget, suggested: str) -> str:
        return QFileDialog.getSaveFileName(parent, "Save plan as", suggested, PLAN_FILTER)[0]

    def xml_open_path(self, parent: QWidget, folder: str) -> str:
        return QFileDialog.getOpenFileName(
            parent, "Import BehaviorTree.CPP XML", folder, XML_FILTER
        )[0]

    def xml_save_path(self, parent: QWidget, suggested: str) -> str:
        return QFileDialog.getSaveFileName(
            parent, "Export as BehaviorTree.CPP XML", suggested, XML_FILTER
        )[0]

    def ask_groot2_port(self, parent: QWidget, current: int) -> int | None:
        """The port to publish runs on for Groot2 (None: cancelled)."""
        port, ok = QInputDialog.getInt(
            parent,
            "Groot2 port",
            "Publish runs for Groot2 on port (it uses this port and the next one):",
            current,
            1,
            65534,
        )
        return int(port) if ok else None

    def ask_text(self, parent: QWidget, title: str, label: str, text: str) -> str | None:
        """A line of text (None: cancelled)."""
        answer, ok = QInputDialog.getText(parent, title, label, text=text)
        return str(answer) if ok else None

    def ask_runs_folder(self, parent: QWidget, current: str) -> str | None:
        """The folder to keep run records in (None: cancelled)."""
        folder = QFileDialog.getExistingDirectory(parent, "Keep run records in", current)
        return folder or None

    def about(self, parent: QWidget, text: str) -> None:
        QMessageBox.about(parent, f"About {APP_TITLE}", text)
