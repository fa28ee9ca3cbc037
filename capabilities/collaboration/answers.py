r"""Answering operator prompts without the Instructor: ``costar run --confirm yes|no|ask``.

- ``yes`` / ``no``: every prompt is answered at once (unattended runs, scripts, tests).
- ``ask`` (the default): the question is printed and a line is read from the input: a line
  starting with "y" answers yes, any other line no. This works with a pipe as well as a
  terminal (``printf 'y\nn\n' | costar run ...``). At the end of the input every open and
  later prompt is answered no: nobody is there to say yes, and a robot must not take
  silence for consent.

The console's listener runs on whichever thread asked (the engine's); it never blocks it:
reading the input happens on a reader thread of its own.
"""

from __future__ import annotations

import collections
import threading
from typing import TextIO

from capabilities.collaboration.console import ConsoleEvent, ConsoleEventKind, OperatorConsole

__all__ = ["CONFIRM_MODES", "PromptAnswerer"]

CONFIRM_MODES = ("yes", "no", "ask")


class PromptAnswerer:
    """Answers a console's prompts as ``mode`` says, printing each question and answer.

    Args:
        console: the cell's operator console.
        mode: "yes", "no" or "ask".
        inp: where "ask" reads answers (one line per prompt).
        out: where questions and automatic answers are printed.
    """

    def __init__(self, console: OperatorConsole, mode: str, inp: TextIO, out: TextIO) -> None:
        if mode not in CONFIRM_MODES:
            raise ValueError(f"confirm mode must be one of {CONFIRM_MODES}, not {mode!r}")
        self._console, self._mode, self._in, self._out = console, mode, inp, out
        self._lock = threading.Lock()
        self._reader: threading.Thread | None = None
        self._lines: collections.deque[str] = collections.deque()  # typed ahead, not yet used
        self._eof = False
        console.add_listener(self._on_event)

    def detach(self) -> None:
        """Stop answering (the reader thread, if any, ends with its input)."""
        self._console.remove_listener(self._on_event)

    def _print(self, text: str) -> None:
        print(text, file=self._out, flush=True)

    def _on_event(self, event: ConsoleEvent) -> None:
        if event.kind is not ConsoleEventKind.PROMPT_SHOWN or event.prompt is None:
            return
        prompt = event.prompt
        if self._mode != "ask":
            self._print(f"operator: {prompt.text} -> {self._mode} (--confirm {self._mode})")
            self._console.answer(prompt.id, self._mode == "yes", f"--confirm {self._mode}")
            return
        self._print(f"operator: {prompt.text} [y/n]")
        with self._lock:
            if self._reader is None:
                self._reader = threading.Thread(
                    target=self._read, name="costar-confirm", daemon=True
                )
                self._reader.start()
        self._match()

    def _read(self) -> None:
        while True:
            line = self._in.readline()
            with self._lock:
                if line:
                    self._lines.append(line)
                else:
                    self._eof = True
            self._match()
            if not line:
                return

    def _match(self) -> None:
        """Give the lines read so far to the open prompts, oldest first; at the end of the
        input, what is left open is answered no.
        """
        # Answered under the lock: two matches at once must not give one prompt two lines.
        unanswered: list[str] = []
        with self._lock:
            for prompt in self._console.pending():
                if self._lines:
                    self._console.answer(prompt.id, _yes(self._lines.popleft()), "the terminal")
                elif self._eof:
                    self._console.answer(prompt.id, False, "end of input")
                    unanswered.append(prompt.text)
        for text in unanswered:
            self._print(f"operator: {text} -> no (end of input)")


def _yes(line: str) -> bool:
    return line.strip().lower().startswith("y")
