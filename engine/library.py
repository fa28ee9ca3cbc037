"""The subtree library: a folder of subtree files that several cells can share.

One versioned JSON file per subtree (``<folder>/<sub/folders>/<Name>.subtree.json``)::

    {"format": "costar-subtree", "format_version": 1, "id": ..., "name": ..., "version": 3,
     "date": "2026-11-24T19:40:00Z", "description": ..., "inputs": [...], "outputs": [...],
     "shared_names": [...], "tree": {...}, "layout": {"nodes": {...}}}

Files are read with the one JSON reader and written atomically (a temporary file, then a
rename), so a reader never sees half a file, whether on a network folder or in a git checkout.
Two Instructors saving at once lose nothing: a save takes a lock file next to the subtree's
file (created with O_EXCL, so exactly one writer holds it), re-reads the version on disk and
refuses, with :class:`LibraryConflict`, to overwrite a version it did not start from; a save
of another subtree goes to another file and another lock. A malformed file is reported by
name and skipped; the rest of the library loads.

Where the library is: the ``--library`` option of a command, else the ``COSTAR_LIBRARY``
environment variable, else the Instructor's setting, else a folder per user
(:func:`default_user_library`). The library shipped with the program (``resources/library``)
is always read after it, read-only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import os
import re
import sys
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from engine.errors import EngineError
from engine.json_reader import JsonFileError, read_json_file
from engine.plan_format import MAX_NESTING, SUBTREE_FIELDS, PlanFileError
from engine.plan_reader import read_subtree
from engine.plan_writer import dump_json, encode_subtree, write_atomic
from engine.spec import SubtreeSpec
from resources import resource_path

__all__ = [
    "LIBRARY_ENV",
    "SHIPPED_LIBRARY",
    "SUBTREE_SUFFIX",
    "Library",
    "LibraryConflict",
    "LibraryEntry",
    "LibraryError",
    "default_user_library",
    "dump_subtree",
    "library_folder",
    "load_subtree",
]

FORMAT = "costar-subtree"
FORMAT_VERSION = 1
SUBTREE_SUFFIX = ".subtree.json"
LIBRARY_ENV = "COSTAR_LIBRARY"
SHIPPED_LIBRARY = resource_path("library")  # package data, found as every shipped file is
_FILE_FIELDS = ("format", "format_version", *SUBTREE_FIELDS)
# A lock older than this was left by a writer that died: it is broken.
STALE_LOCK_SECONDS = 30.0
LOCK_WAIT_SECONDS = 10.0


class LibraryError(EngineError):
    """A library operation that cannot be done (a folder not writable, a lock not taken)."""


class LibraryConflict(LibraryError):
    """Someone else saved a version of this subtree since the one this save started from."""


def default_user_library() -> Path:
    """The per-user library folder (``~/.local/share/costar/library`` on Linux)."""
    if sys.platform == "win32":
        base = Path(os.environ.get("APPDATA", Path.home() / "AppData" / "Roaming"))
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "costar" / "library"


def library_folder(option: str | None = None, setting: str | None = None) -> Path:
    """The writable library folder: the option, else $COSTAR_LIBRARY, else the setting."""
    chosen = option or os.environ.get(LIBRARY_ENV) or setting
    return Path(chosen).expanduser() if chosen else default_user_library()


def dump_subtree(subtree: SubtreeSpec) -> str:
    """The file text of a subtree (deterministic: save -> load -> save gives the same bytes)."""
    doc = {"format": FORMAT, "format_version": FORMAT_VERSION, **encode_subtree(subtree)}
    return dump_json(doc, subtree.name)


def load_subtree(path: str | os.PathLike[str]) -> SubtreeSpec:
    """Read one subtree file.

    Raises:
        PlanFileError: the file is missing, unreadable or not a subtree file.
    """
    file = os.fspath(path)
    doc = read_json_file(file, "subtree", max_depth=MAX_NESTING, error=PlanFileError)
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        got = doc.get("format") if isinstance(doc, dict) else doc
        raise PlanFileError(file, "$.format", repr(FORMAT), repr(got))
    if doc.get("format_version") != FORMAT_VERSION:
        raise PlanFileError(
            file,
            "$.format_version",
            f"format_version {FORMAT_VERSION}",
            repr(doc.get("format_version")),
        )
    return read_subtree(doc, file, _FILE_FIELDS)


def file_name(name: str) -> str:
    """A subtree's file name: its name with only safe characters."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "subtree"
    return f"{stem}{SUBTREE_SUFFIX}"


@dataclass(frozen=True)
class LibraryEntry:
    """One subtree file of the library.

    Attributes:
        subtree: what the file holds.
        path: the file.
        folder: its folder relative to the library's root ("" at the top, "kitting").
        shipped: True for the read-only library shipped with the program.
    """

    subtree: SubtreeSpec
    path: Path
    folder: str
    shipped: bool = False


@dataclass
class Library:
    """A library folder (writable) and the shipped one (read-only), read afresh by :meth:`scan`.

    Args:
        root: the writable folder (made on the first save).
        shipped: read-only folders read after it (default: the shipped library).
    """

    root: Path
    shipped: Sequence[Path] = (SHIPPED_LIBRARY,)
    entries: list[LibraryEntry] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    def scan(self) -> Library:
        """Read every subtree file; a malformed one goes to :attr:`problems`, by name."""
        self.entries, self.problems = [], []
        for base, shipped in [(self.root, False), *((p, True) for p in self.shipped)]:
            for path in sorted(_subtree_files(base)):
                try:
                    subtree = load_subtree(path)
                except JsonFileError as exc:
                    self.problems.append(str(exc))
                    continue
                folder = path.parent.relative_to(base).as_posix()
                self.entries.append(
                    LibraryEntry(subtree, path, "" if folder == "." else folder, shipped)
                )
        return self

    def folders(self) -> list[str]:
        return sorted({entry.folder for entry in self.entries})

    def latest(self, subtree_id: str) -> SubtreeSpec | None:
        """The newest version of a subtree in the library (validation's SubtreeSource)."""
        found = [e.subtree for e in self.entries if e.subtree.id == subtree_id]
        return max(found, key=lambda s: s.version) if found else None

    def entry(self, subtree_id: str) -> LibraryEntry | None:
        """The entry of a subtree's newest version, the writable folder's before the shipped."""
        found = [e for e in self.entries if e.subtree.id == subtree_id]
        return max(found, key=lambda e: (e.subtree.version, not e.shipped)) if found else None

    def search(self, text: str) -> list[LibraryEntry]:
        """Entries whose name, description, folder or ports contain every word of ``text``."""
        words = text.lower().split()
        found = []
        for entry in self.entries:
            sub = entry.subtree
            ports = " ".join(p.name for p in [*sub.inputs, *sub.outputs])
            hay = f"{sub.name} {sub.description} {entry.folder} {ports}".lower()
            if all(word in hay for word in words):
                found.append(entry)
        return found

    def save(
        self, subtree: SubtreeSpec, folder: str = "", base_version: int | None = None
    ) -> SubtreeSpec:
        """Save a new version of a subtree; returns it (version and date set).

        Args:
            subtree: what to save (its ``version`` is ignored: the library counts).
            folder: where a new subtree goes, relative to the root ("kitting/plates").
            base_version: the version this edit started from; None for a new subtree.

        Raises:
            LibraryConflict: the file holds another version than ``base_version`` (someone
                saved in between), or another subtree already has the file name.
            LibraryError: the folder cannot be written or the lock cannot be taken.
        """
        target = self._target(subtree, folder)
        with _locked(target):
            current = _current(target)
            if current is not None and current.id != subtree.id:
                raise LibraryConflict(
                    f"{target}: another subtree called {current.name!r} is already there"
                )
            on_disk = current.version if current is not None else self._shipped_version(subtree.id)
            if on_disk != base_version:
                raise LibraryConflict(_conflict_text(target, subtree, on_disk, base_version))
            saved = dataclasses.replace(subtree, version=(on_disk or 0) + 1, date=_now())
            try:
                write_atomic(target, dump_subtree(saved).encode("utf-8"))
            except PlanFileError as exc:
                raise LibraryError(str(exc)) from exc
        return saved

    def _shipped_version(self, subtree_id: str) -> int | None:
        """A shipped subtree's version: a changed copy goes to the writable folder, one up."""
        found = [
            e.subtree.version for e in self.entries if e.shipped and e.subtree.id == subtree_id
        ]
        return max(found) if found else None

    def _target(self, subtree: SubtreeSpec, folder: str) -> Path:
        existing = next(
            (e for e in self.entries if e.subtree.id == subtree.id and not e.shipped), None
        )
        if existing is not None:
            return existing.path
        shipped = next((e for e in self.entries if e.subtree.id == subtree.id), None)
        if shipped is not None and not folder:
            folder = shipped.folder  # a changed shipped subtree keeps its folder
        parts = [p for p in Path(folder).parts if p not in ("", ".", "..")]
        place = self.root.joinpath(*parts)
        try:
            place.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise LibraryError(f"{place}: cannot make the library folder: {exc.strerror}") from exc
        return place / file_name(subtree.name)


def _subtree_files(base: Path) -> Iterator[Path]:
    if not base.is_dir():
        return
    for path in base.rglob(f"*{SUBTREE_SUFFIX}"):
        if not path.name.startswith("."):  # temporary files of a save in progress
            yield path


def _current(target: Path) -> SubtreeSpec | None:
    if not target.exists():
        return None
    try:
        return load_subtree(target)
    except JsonFileError as exc:
        raise LibraryError(f"cannot save over a broken file: {exc}") from exc


def _conflict_text(
    target: Path, subtree: SubtreeSpec, on_disk: int | None, base: int | None
) -> str:
    if base is None:
        return f"{target}: {subtree.name!r} is already in the library (version {on_disk})"
    if on_disk is None:
        return f"{target}: {subtree.name!r} was removed from the library since version {base}"
    return (
        f"{target}: {subtree.name!r} was saved by someone else (version {on_disk}) since "
        f"version {base} was opened: reload it and save again"
    )


def _now() -> str:
    return datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


@contextlib.contextmanager
def _locked(target: Path) -> Iterator[None]:
    """Hold ``.<file>.lock`` next to the target: one writer at a time, across processes."""
    lock = target.with_name(f".{target.name}.lock")
    deadline = time.monotonic() + LOCK_WAIT_SECONDS
    while True:
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            break
        except FileExistsError:
            _break_if_stale(lock)
            if time.monotonic() > deadline:
                raise LibraryError(f"{lock}: another Instructor is saving; try again") from None
            time.sleep(0.01)  # another writer holds it for the few ms of its write
        except OSError as exc:
            raise LibraryError(f"{lock}: cannot take the lock: {exc.strerror}") from exc
    try:
        os.write(fd, f"{os.getpid()}\n".encode())
        os.close(fd)
        yield
    finally:
        with contextlib.suppress(OSError):
            os.unlink(lock)


def _break_if_stale(lock: Path) -> None:
    with contextlib.suppress(OSError):
        if time.time() - lock.stat().st_mtime > STALE_LOCK_SECONDS:
            lock.unlink()
