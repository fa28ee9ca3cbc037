"""The operator panel: the plan's questions with Yes/No, and the operator's Continue button.

It shows the cell's ``operator`` console (an OperatorConsole, Qt-free). The console tells
its listeners from any thread (the engine's, a pedal poller's); the panel re-emits each
event through a queued signal, so every widget change happens in the GUI thread. When a
question arrives the panel highlights itself and emits ``prompt_shown`` so the window can
bring its dock forward.
"""

from __future__ import annotations

import functools
from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QApplication,
    QFrame,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from capabilities.collaboration.console import (
    ConsoleEvent,
    ConsoleEventKind,
    OperatorConsole,
    Prompt,
)

__all__ = ["OperatorPanel", "PromptRow"]

# The panel's highlight while a question waits (a warm frame the eye catches from afar).
_WAITING_STYLE = "#OperatorPanel { border: 2px solid #e08a00; border-radius: 4px; }"


def _unlink(link: dict[str, Any], *_: Any) -> None:
    console = link.get("console")
    if console is not None:
        console.remove_listener(link["listener"])


class PromptRow(QFrame):
    """One open question: its text, who asks, and Yes / No buttons.

    Signals:
        answered(str, bool): the prompt's id and the answer given.
    """

    answered = Signal(str, bool)

    def __init__(self, prompt: Prompt, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.prompt_id = prompt.id
        self.number = prompt.number
        self.setObjectName(f"prompt_{prompt.id}")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.text_label = QLabel(prompt.text)
        self.text_label.setWordWrap(True)
        font = self.text_label.font()
        font.setPointSizeF(font.pointSizeF() * 1.25)
        font.setBold(True)
        self.text_label.setFont(font)
        self.source_label = QLabel(f"asked by {prompt.source}" if prompt.source else "")
        self.yes_button = QPushButton("Yes")
        self.no_button = QPushButton("No")
        for button, yes in ((self.yes_button, True), (self.no_button, False)):
            button.setMinimumHeight(36)
            button.clicked.connect(lambda _=False, yes=yes: self._answer(yes))
        buttons = QHBoxLayout()
        buttons.addWidget(self.yes_button)
        buttons.addWidget(self.no_button)
        layout = QVBoxLayout(self)
        layout.addWidget(self.text_label)
        if prompt.source:
            layout.addWidget(self.source_label)
        layout.addLayout(buttons)

    def _answer(self, yes: bool) -> None:
        # Disabled at once: the row goes when the console says the prompt closed.
        self.yes_button.setEnabled(False)
        self.no_button.setEnabled(False)
        self.answered.emit(self.prompt_id, yes)


class OperatorPanel(QWidget):
    """Open questions of the running plan and the operator's buttons.

    Signals:
        prompt_shown(str): a question arrived (its text): show and raise the panel's dock.
        prompts_changed(int): how many questions are open now.
        button_pressed(str): an operator button was pressed (here, or by a pedal).
    """

    prompt_shown = Signal(str)
    prompts_changed = Signal(int)
    button_pressed = Signal(str)
    _event_received = Signal(object)  # from the console's threads to the GUI thread

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("OperatorPanel")
        self.setAttribute(Qt.WidgetAttribute.WA_StyledBackground, True)
        self._console: OperatorConsole | None = None
        self._rows: dict[str, PromptRow] = {}
        self.status_label = QLabel()
        self.status_label.setWordWrap(True)
        self.continue_button = QPushButton("Continue")
        self.continue_button.setObjectName("ContinueButton")
        self.continue_button.setToolTip("Press the operator's Continue button (as the foot pedal)")
        self.continue_button.setMinimumHeight(40)
        self.continue_button.clicked.connect(lambda: self.press("continue"))
        self._prompt_box = QVBoxLayout()
        layout = QVBoxLayout(self)
        layout.addWidget(self.status_label)
        layout.addLayout(self._prompt_box)
        layout.addStretch(1)
        layout.addWidget(self.continue_button)
        self._event_received.connect(self._apply, Qt.ConnectionType.QueuedConnection)
        # When the widget is destroyed first, the console must stop calling into it.
        self._link: dict[str, Any] = {"console": None, "listener": self._heard}
        self.destroyed.connect(functools.partial(_unlink, self._link))
        self.set_console(None)

    # ------------------------------------------------------------------ API

    @property
    def console(self) -> OperatorConsole | None:
        return self._console

    def set_console(self, console: OperatorConsole | None) -> None:
        """Show another cell's console (None: the cell has none; the panel is disabled)."""
        if self._console is not None:
            self._console.remove_listener(self._heard)
        self._console = console
        self._link["console"] = console
        for prompt_id in list(self._rows):
            self._remove_row(prompt_id)
        if console is not None:
            console.add_listener(self._heard)
            for prompt in console.pending():
                self._add_row(prompt)
        self.continue_button.setEnabled(console is not None)
        self._update_state()

    def rows(self) -> list[PromptRow]:
        """The open questions' rows, oldest first."""
        return sorted(self._rows.values(), key=lambda row: row.number)

    def press(self, button: str = "continue") -> None:
        """Press an operator button on the console."""
        if self._console is not None:
            self._console.press(button, "the Instructor")

    # ------------------------------------------------------------------ console events

    def _heard(self, event: ConsoleEvent) -> None:
        # Any thread: only hand the event over; the queued connection delivers it in the
        # GUI thread.
        self._event_received.emit(event)

    def _apply(self, event: Any) -> None:
        if event.kind is ConsoleEventKind.PROMPT_SHOWN and event.prompt is not None:
            if event.prompt.closed or self._console is None:
                return  # answered or withdrawn before it reached us
            self._add_row(event.prompt)
            self._update_state()
            self._call_attention()
            self.prompt_shown.emit(event.prompt.text)
        elif event.kind is ConsoleEventKind.PROMPT_CLOSED and event.prompt is not None:
            self._remove_row(event.prompt.id)
            self._update_state()
        elif event.kind is ConsoleEventKind.BUTTON_PRESSED:
            self.button_pressed.emit(event.button)

    def _add_row(self, prompt: Prompt) -> None:
        if prompt.id in self._rows:
            return
        row = PromptRow(prompt, self)
        row.answered.connect(self._answer)
        # Events from several threads may arrive out of order: keep the order of asking.
        index = sum(1 for other in self._rows.values() if other.number < prompt.number)
        self._rows[prompt.id] = row
        self._prompt_box.insertWidget(index, row)

    def _remove_row(self, prompt_id: str) -> None:
        row = self._rows.pop(prompt_id, None)
        if row is not None:
            self._prompt_box.removeWidget(row)
            row.deleteLater()

    def _answer(self, prompt_id: str, yes: bool) -> None:
        if self._console is not None:
            self._console.answer(prompt_id, yes, "the Instructor")

    def _update_state(self) -> None:
        count = len(self._rows)
        if self._console is None:
            text = "This cell has no operator console."
        elif count:
            text = f"The robot waits for your answer ({count} question{'s' * (count > 1)})."
        else:
            text = "No questions from the robot."
        self.status_label.setText(text)
        self.setStyleSheet(_WAITING_STYLE if count else "")
        self.prompts_changed.emit(count)

    def _call_attention(self) -> None:
        window = self.window()
        if window is not None and window.isVisible():
            QApplication.alert(window)  # flashes the task bar entry until the window is used
