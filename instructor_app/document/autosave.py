"""Crash recovery: the dirty plan is written to a recovery folder every 30 s.

Each open document has one recovery file (``<id>.costar.json``, the serialized plan) and a
sidecar (``<id>.recovery.json``: the original path, the time, the process id). Both are
written atomically (temp file + rename), the plan first, so a sidecar always names a
complete plan. They are removed when the document is saved, becomes clean again, or is
closed cleanly; what is left after a crash is found by :func:`find_recoveries` at the next
start.
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QObject, QStandardPaths, QTimer, Signal

from engine.json_reader import JsonFileError, JsonReader, read_json_file
from engine.processes import process_alive
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.errors import InstructorError

_log = logging.getLogger(__name__)

__all__ = [
    "AutosaveError",
    "Autosaver",
    "Recovery",
    "default_recovery_folder",
    "find_recoveries",
    "offer_recoveries",
    "DEFAULT_INTERVAL_MS",
]

DEFAULT_INTERVAL_MS = 30_000
_PLAN_SUFFIX = ".costar.json"
_SIDECAR_SUFFIX = ".recovery.json"
_FORMAT = "costar-recovery"


class AutosaveError(InstructorError):
    """A recovery file could not be read or written."""


def default_recovery_folder() -> Path:
    """``<AppDataLocation>/recovery`` (the application and organisation names must be set)."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".costar-instructor") / "recovery"


@dataclass(frozen=True)
class Recovery:
    """A plan left behind by a session that did not end cleanly.

    Attributes:
        plan_file: the recovery copy of the plan.
        sidecar: its description file.
        original: the file the plan was being edited as (None: never saved).
        saved_at: when the copy was written (seconds since the epoch).
        name: the plan's name.
    """

    plan_file: Path
    sidecar: Path
    original: str | None
    saved_at: float
    name: str

    def text(self) -> str:
        try:
            return self.plan_file.read_text(encoding="utf-8")
        except OSError as exc:
            raise AutosaveError(f"cannot read {self.plan_file}: {exc}") from exc

    def describe(self) -> str:
        when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.saved_at))
        where = self.original or "a plan never saved"
        return f"{self.name or 'Untitled plan'} ({where}), autosaved {when}"

    def discard(self) -> None:
        for path in (self.sidecar, self.plan_file):
            path.unlink(missing_ok=True)


def _write_atomically(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=path.name, suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def find_recoveries(folder: Path, exclude: set[Path] | None = None) -> list[Recovery]:
    """Recoveries in ``folder``, newest first.

    Skips the files of another Instructor that is still running (its pid is alive), files in
    ``exclude`` (this window's own) and unreadable sidecars.
    """
    found: list[Recovery] = []
    skip = {p.resolve() for p in (exclude or set())}
    for sidecar in Path(folder).glob(f"*{_SIDECAR_SUFFIX}"):
        plan_file = sidecar.with_name(sidecar.name[: -len(_SIDECAR_SUFFIX)] + _PLAN_SUFFIX)
        if plan_file.resolve() in skip or not plan_file.exists():
            continue
        try:
            recovery = _read_sidecar(sidecar, plan_file)
        except JsonFileError as exc:  # another version's or a broken sidecar: not ours to offer
            _log.info("recovery sidecar skipped: %s", exc)
            continue
        if recovery is not None:
            found.append(recovery)
    return sorted(found, key=lambda r: r.saved_at, reverse=True)


def _read_sidecar(sidecar: Path, plan_file: Path) -> Recovery | None:
    """The recovery a sidecar describes; None when it is another running Instructor's.

    Raises:
        JsonFileError: the sidecar is not one of ours, naming the file and the field.
    """
    doc = JsonReader(read_json_file(sidecar, "recovery sidecar"), str(sidecar))
    doc.as_object()
    if doc.get("format") != _FORMAT:
        doc.fail(f"format {_FORMAT!r}", key="format")
    pid = doc.get("pid")
    mine = pid == os.getpid()  # this window's own copy is excluded by path, not here
    if isinstance(pid, int) and not isinstance(pid, bool) and not mine and process_alive(pid):
        return None  # a null or missing pid is nobody's: offered
    original = doc.get("original")
    saved_at = doc.number("saved_at", default=0.0)
    name = doc.get("name")
    return Recovery(
        plan_file,
        sidecar,
        original if isinstance(original, str) and original else None,
        saved_at,
        name if isinstance(name, str) else "",
    )


class Autosaver(QObject):
    """Writes the document's recovery copy while it is dirty.

    Args:
        document: the document to protect.
        folder: the recovery folder (default :func:`default_recovery_folder`).
        interval_ms: how often to write while dirty.

    Signals:
        written(str): the recovery file was written (its path).
        failed(str): writing failed (the message); autosave keeps trying.
    """

    written = Signal(str)
    failed = Signal(str)

    def __init__(
        self,
        document: PlanDocument,
        folder: Path | None = None,
        interval_ms: int = DEFAULT_INTERVAL_MS,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self.document = document
        self.folder = Path(folder) if folder is not None else default_recovery_folder()
        key = uuid.uuid4().hex
        self.plan_file = self.folder / f"{key}{_PLAN_SUFFIX}"
        self.sidecar = self.folder / f"{key}{_SIDECAR_SUFFIX}"
        self._timer = QTimer(self)
        self._timer.setInterval(interval_ms)
        self._timer.timeout.connect(self._on_timer)
        document.dirty_changed.connect(self._on_dirty_changed)
        self._timer.start()

    def write_now(self) -> Path | None:
        """Write the recovery copy if the document is dirty; returns its path."""
        if not self.document.dirty:
            return None
        path = self.document.path
        sidecar = {
            "format": _FORMAT,
            "format_version": 1,
            "original": str(path) if path else None,
            "saved_at": time.time(),
            "pid": os.getpid(),
            "name": self.document.plan.name,
        }
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            _write_atomically(self.plan_file, self.document.serialized())
            _write_atomically(self.sidecar, json.dumps(sidecar, indent=2))
        except OSError as exc:
            self.failed.emit(f"autosave to {self.folder} failed: {exc}")
            return None
        self.written.emit(str(self.plan_file))
        return self.plan_file

    def discard(self) -> None:
        """Remove this document's recovery copy (saved, clean again, or closed cleanly)."""
        for path in (self.sidecar, self.plan_file):
            path.unlink(missing_ok=True)

    def stop(self) -> None:
        """Stop writing (the window closes); removes the copy."""
        self._timer.stop()
        self.discard()

    def _on_timer(self) -> None:
        self.write_now()

    def _on_dirty_changed(self, dirty: bool) -> None:
        if not dirty:
            self.discard()


def offer_recoveries(
    document: PlanDocument,
    autosaver: Autosaver,
    ask: Callable[[str], bool],
    report: Callable[[str], None],
) -> Recovery | None:
    """Offer each recovery in the autosaver's folder (newest first) until one is accepted.

    An accepted one is loaded into ``document`` (dirty, with its original path) and its files
    are removed: the document's own autosaver protects it from then on. Declined ones are
    deleted. Returns the restored recovery, or None.

    Args:
        document: where to restore.
        autosaver: the document's autosaver (its own file is never offered).
        ask: shows a recovery's description and answers whether to restore it.
        report: shows an error (a recovery that cannot be read).
    """
    for recovery in find_recoveries(autosaver.folder, exclude={autosaver.plan_file}):
        if not ask(recovery.describe()):
            recovery.discard()
            continue
        try:
            document.load_text(recovery.text(), recovery.original)
        except (DocumentError, AutosaveError) as exc:
            report(f"{recovery.describe()}: {exc}")
            continue
        recovery.discard()
        autosaver.write_now()
        return recovery
    return None
