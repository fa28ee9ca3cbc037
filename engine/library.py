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

A lock names its writer (PID, host, start time). A writer killed mid-save (kill -9, a power
cut) leaves its lock and maybe a temporary file: the next save breaks a lock whose process is
gone from this host, or that is unreadable or older than :data:`STALE_LOCK_SECONDS`, at once,
and removes the temporary files of the file it now holds the lock of; :meth:`Library.scan`
removes temporary files next to a stale lock, or older than :data:`STALE_TEMP_SECONDS`. A
live lock of another host is waited for, at most :attr:`Library.lock_wait` seconds.

Folders are relative to the library's root and stay inside it (:func:`check_folder`); a file
name keeps the letters and digits of any script (:func:`file_name`).

Where the library is: the ``--library`` option of a command, else the ``COSTAR_LIBRARY``
environment variable, else the Instructor's setting, else a folder per user
(:func:`default_user_library`). The library shipped with the program (``resources/library``)
is always read after it, read-only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime
import hashlib
import json
import os
import re
import socket
import sys
import time
import unicodedata
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath

from engine.errors import EngineError
from engine.json_reader import JsonFileError, read_json_file
from engine.plan_format import MAX_NESTING, SUBTREE_FIELDS, PlanFileError
from engine.plan_reader import read_subtree
from engine.plan_writer import dump_json, encode_subtree, has_conditions, write_atomic
from engine.processes import process_alive
from engine.spec import SubtreeSpec
from engine.types import with_article
from resources import resource_path

__all__ = [
    "LIBRARY_ENV",
    "SHIPPED_LIBRARY",
    "SUBTREE_SUFFIX",
    "Library",
    "LibraryConflict",
    "LibraryEntry",
    "LibraryError",
    "check_folder",
    "default_user_library",
    "dump_subtree",
    "file_name",
    "library_folder",
    "load_subtree",
]

FORMAT = "costar-subtree"
# 2: nodes with pre- and post-conditions; a subtree without any is written as 1, so older
# programs keep reading it.
FORMAT_VERSION = 2
PLAIN_FORMAT_VERSION = 1
READABLE_VERSIONS = (1, 2)
SUBTREE_SUFFIX = ".subtree.json"
LIBRARY_ENV = "COSTAR_LIBRARY"
SHIPPED_LIBRARY = resource_path("library")  # package data, found as every shipped file is
_FILE_FIELDS = ("format", "format_version", *SUBTREE_FIELDS)
# A lock older than this was left by a writer that died (or hangs): it is broken. A save holds
# its lock for the few milliseconds of one file write, seconds at most on a slow network folder.
STALE_LOCK_SECONDS = 30.0
# A lock file without a readable owner yet: its writer is between creating it and writing it.
UNREADABLE_LOCK_GRACE_SECONDS = 2.0
# How long a save waits for a live lock (another host's, or another thread's of this process).
LOCK_WAIT_SECONDS = 10.0
# A temporary file of a save older than this is a leftover of a writer that died.
STALE_TEMP_SECONDS = 600.0
_HOST = socket.gethostname()
# write_atomic's temporary file of ``<name>``: ``.<name>.<8 hex digits>.tmp``.
_TEMP = re.compile(r"\.(?P<target>.+\.subtree\.json)\.[0-9a-f]{8}\.tmp")
# A file name: the stem at most this many UTF-8 bytes, so that the lock's and the temporary
# file's names (the longest, 14 bytes more than the file's) stay within the usual 255.
_MAX_STEM_BYTES = 200


class LibraryError(EngineError):
    """A library operation that cannot be done (a folder not writable, a lock not taken)."""


class LibraryConflict(LibraryError):
    """Someone else saved a version of this subtree since the one this save started from."""


def user_data_folder(leaf: str) -> Path:
    """A per-user data folder of the application (``~/.local/share/costar/LEAF`` on Linux)."""
    if sys.platform == "win32":
        base = Path(os.environ.get("APPDATA", Path.home() / "AppData" / "Roaming"))
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "costar" / leaf


def chosen_folder(option: str | None, variable: str, setting: str | None, leaf: str) -> Path:
    """A folder the user may choose: a command's option, else the environment ``variable``,
    else the Instructor's setting, else the user's data folder ``leaf``.
    """
    chosen = option or os.environ.get(variable) or setting
    return Path(chosen).expanduser() if chosen else user_data_folder(leaf)


def default_user_library() -> Path:
    """The per-user library folder (``~/.local/share/costar/library`` on Linux)."""
    return user_data_folder("library")


def library_folder(option: str | None = None, setting: str | None = None) -> Path:
    """The writable library folder: the option, else $COSTAR_LIBRARY, else the setting."""
    return chosen_folder(option, LIBRARY_ENV, setting, "library")


def dump_subtree(subtree: SubtreeSpec) -> str:
    """The file text of a subtree (deterministic: save -> load -> save gives the same bytes)."""
    version = FORMAT_VERSION if has_conditions(subtree.tree) else PLAIN_FORMAT_VERSION
    doc = {"format": FORMAT, "format_version": version, **encode_subtree(subtree)}
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
    version = doc.get("format_version")
    if version not in READABLE_VERSIONS or isinstance(version, bool):
        raise PlanFileError(
            file,
            "$.format_version",
            "format_version " + " or ".join(str(v) for v in READABLE_VERSIONS),
            repr(version),
        )
    return read_subtree(doc, file, _FILE_FIELDS)


def file_name(name: str) -> str:
    """A subtree's file name: its name with the letters and digits of any script kept.

    The name is NFKC-normalised; letters, marks and digits of every script, ``_``, ``.`` and
    ``-`` are kept, every run of other characters becomes one ``_`` (an ASCII name gets the
    file name it always had: ``"Pick part"`` -> ``Pick_part.subtree.json``, ``"名前"`` ->
    ``名前.subtree.json``). A name with nothing readable left (``"!!!"``, ``"🤖"``) gets
    ``subtree-`` and a short hash of the name, and a very long one is cut and gets the hash
    too, so that different names keep different files.
    """
    kept: list[str] = []
    for char in unicodedata.normalize("NFKC", name):
        if char in "_.-" or unicodedata.category(char)[0] in "LMN":
            kept.append(char)
        elif not kept or kept[-1] != "\0":
            kept.append("\0")  # a run of unsafe characters: one "_"
    stem = "".join(kept).replace("\0", "_").strip("._")
    digest = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    if not stem:
        stem = f"subtree-{digest}"
    elif len(stem.encode("utf-8")) > _MAX_STEM_BYTES:
        cut = stem.encode("utf-8")[: _MAX_STEM_BYTES - 9].decode("utf-8", "ignore")
        stem = f"{cut}-{digest}"
    return f"{stem}{SUBTREE_SUFFIX}"


def check_folder(root: Path, folder: str) -> Path:
    r"""The library folder ``folder`` names: relative to ``root`` and inside it.

    Raises:
        LibraryError: ``folder`` is absolute (``/x``, ``C:\x``, ``C:/x``, ``\\server\share``),
            has a ``..`` part, a control character (NUL included) or a ``:``, or leads out of
            the library through a symbolic link.
    """
    expected = "a folder inside the library, relative to it, like 'kitting/plates'"

    def refused(why: str) -> LibraryError:
        return LibraryError(f"library folder {folder!r} refused: {why}; expected {expected}")

    if not isinstance(folder, str):
        raise refused(f"{with_article(type(folder).__name__)}, not text")
    if any(ord(char) < 32 or ord(char) == 127 for char in folder):
        raise refused("it holds a control character")
    windows = PureWindowsPath(folder)
    if PurePosixPath(folder).is_absolute() or windows.drive or windows.root:
        raise refused("it is an absolute path")
    if ":" in folder:
        raise refused("it holds a ':' (a drive or a stream on Windows)")
    parts = [part for part in re.split(r"[\\/]", folder) if part not in ("", ".")]
    if ".." in parts:
        raise refused("it has a '..' part")
    place = root.joinpath(*parts)
    try:
        inside = place.resolve().is_relative_to(root.resolve())
    except (OSError, RuntimeError) as exc:  # a symbolic link loop
        raise refused(f"it cannot be resolved: {exc}") from exc
    if not inside:
        raise refused(f"it leads out of the library (to {place.resolve()})")
    return place


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
        lock_wait: how long a save waits for a live lock before it fails, in seconds.
    """

    root: Path
    shipped: Sequence[Path] = (SHIPPED_LIBRARY,)
    entries: list[LibraryEntry] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    lock_wait: float = LOCK_WAIT_SECONDS

    def scan(self) -> Library:
        """Read every subtree file; a malformed one goes to :attr:`problems`, by name.

        Temporary files a dead writer left in the writable folder are removed first. The lists
        are replaced whole, so a save on another thread sees the old or the new ones.
        """
        _remove_dead_temps(self.root)
        entries: list[LibraryEntry] = []
        problems: list[str] = []
        for base, shipped in [(self.root, False), *((p, True) for p in self.shipped)]:
            for path in sorted(_subtree_files(base)):
                try:
                    subtree = load_subtree(path)
                except JsonFileError as exc:
                    problems.append(str(exc))
                    continue
                folder = path.parent.relative_to(base).as_posix()
                entries.append(
                    LibraryEntry(subtree, path, "" if folder == "." else folder, shipped)
                )
        self.entries, self.problems = entries, problems
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
            folder: where a new subtree goes, relative to the root ("kitting/plates"); it
                must stay inside the library (:func:`check_folder`).
            base_version: the version this edit started from; None for a new subtree.

        Raises:
            LibraryConflict: the file holds another version than ``base_version`` (someone
                saved in between), or another subtree already has the file name.
            LibraryError: the folder is refused or cannot be written, or the lock cannot be
                taken within :attr:`lock_wait`.
        """
        check_folder(self.root, folder)
        entries = self.entries  # one list throughout, whatever scan() does meanwhile
        target = self._target(subtree, folder, entries)
        with _locked(target, self.lock_wait):
            _remove_temps_of(target)  # its writer held this lock: it is gone
            current = _current(target)
            if current is not None and current.id != subtree.id:
                raise LibraryConflict(
                    f"{target}: another subtree called {current.name!r} is already there"
                )
            on_disk = (
                current.version if current is not None else _shipped_version(entries, subtree.id)
            )
            if on_disk != base_version:
                raise LibraryConflict(_conflict_text(target, subtree, on_disk, base_version))
            saved = dataclasses.replace(subtree, version=(on_disk or 0) + 1, date=_now())
            try:
                write_atomic(target, dump_subtree(saved).encode("utf-8"))
            except PlanFileError as exc:
                raise LibraryError(str(exc)) from exc
        return saved

    def _target(self, subtree: SubtreeSpec, folder: str, entries: list[LibraryEntry]) -> Path:
        existing = next((e for e in entries if e.subtree.id == subtree.id and not e.shipped), None)
        if existing is not None:
            return existing.path
        shipped = next((e for e in entries if e.subtree.id == subtree.id), None)
        if shipped is not None and not folder:
            folder = shipped.folder  # a changed shipped subtree keeps its folder
        place = check_folder(self.root, folder)
        try:
            place.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise LibraryError(f"{place}: cannot make the library folder: {exc.strerror}") from exc
        check_folder(self.root, folder)  # a link put there meanwhile
        return place / file_name(subtree.name)


def _shipped_version(entries: list[LibraryEntry], subtree_id: str) -> int | None:
    """A shipped subtree's version: a changed copy goes to the writable folder, one up."""
    found = [e.subtree.version for e in entries if e.shipped and e.subtree.id == subtree_id]
    return max(found) if found else None


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
def _locked(target: Path, wait: float = LOCK_WAIT_SECONDS) -> Iterator[None]:
    """Hold ``.<file>.lock`` next to the target: one writer at a time, across processes.

    The lock holds ``{"pid", "host", "started"}``; a stale one (:func:`_is_stale`) is broken
    at once, a live one is waited for at most ``wait`` seconds.
    """
    lock = target.with_name(f".{target.name}.lock")
    deadline = time.monotonic() + wait
    while True:
        try:
            fd = os.open(lock, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            break
        except FileExistsError:
            if _break_if_stale(lock) and time.monotonic() <= deadline:
                continue
            if time.monotonic() > deadline:
                raise LibraryError(
                    f"{lock}: another Instructor is saving this subtree ({_owner_text(lock)}); "
                    "try again"
                ) from None
            time.sleep(0.01)  # another writer holds it for the few ms of its write
        except OSError as exc:
            raise LibraryError(f"{lock}: cannot take the lock: {exc.strerror}") from exc
    try:
        owner = {"pid": os.getpid(), "host": _HOST, "started": time.time()}
        os.write(fd, json.dumps(owner).encode("utf-8"))
        os.close(fd)
        yield
    finally:
        with contextlib.suppress(OSError):
            os.unlink(lock)


def _read_owner(lock: Path) -> dict[str, object] | None:
    """The lock's owner, None when the file holds none (being written, or not ours)."""
    try:
        with open(lock, "rb") as handle:
            text = handle.read(4096)
        owner = json.loads(text)
    except (OSError, ValueError):
        return None
    if isinstance(owner, int):  # an earlier Instructor's lock: its PID only, host unknown
        owner = {"pid": owner, "host": ""}
    if (
        not isinstance(owner, dict)
        or not isinstance(owner.get("pid"), int)
        or not isinstance(owner.get("host"), str)
    ):
        return None
    return owner


def _owner_text(lock: Path) -> str:
    owner = _read_owner(lock)
    return f"process {owner['pid']} on {owner['host']}" if owner else "an unknown writer"


def _is_stale(owner: dict[str, object] | None, age: float) -> bool:
    """A lock nobody holds: its process is gone from this host, it names no owner (and is not
    being written), or it is older than any save takes.
    """
    if age > STALE_LOCK_SECONDS:
        return True
    if owner is None:
        return age > UNREADABLE_LOCK_GRACE_SECONDS
    pid = owner["pid"]
    if owner["host"] == _HOST and isinstance(pid, int):
        return not process_alive(pid)
    return False  # another host's live lock: waited for


def _break_if_stale(lock: Path) -> bool:
    """Remove ``lock`` if it is stale; True when it is gone (taking it can be tried again).

    The file is removed only if it is still the one judged (same inode and time): a lock
    broken and taken again by another writer meanwhile is left alone.
    """
    try:
        before = os.stat(lock)
    except FileNotFoundError:
        return True
    except OSError:
        return False
    if not _is_stale(_read_owner(lock), time.time() - before.st_mtime):
        return False
    try:
        now = os.stat(lock)
        if (now.st_ino, now.st_mtime_ns, now.st_size) != (
            before.st_ino,
            before.st_mtime_ns,
            before.st_size,
        ):
            return False
        os.unlink(lock)
    except FileNotFoundError:
        return True
    except OSError:
        return False
    return True


def _remove_temps_of(target: Path) -> None:
    """Remove the temporary files of ``target`` (called holding its lock: their writer held
    it too, so it is gone).
    """
    with contextlib.suppress(OSError):
        for path in target.parent.iterdir():
            match = _TEMP.fullmatch(path.name)
            if match and match["target"] == target.name:
                with contextlib.suppress(OSError):
                    path.unlink()


def _remove_dead_temps(root: Path) -> None:
    """Remove the library's temporary files whose writer is gone: its lock is stale (a killed
    save leaves both), or the file is older than any save takes.
    """
    if not root.is_dir():
        return
    now = time.time()
    with contextlib.suppress(OSError):
        for path in root.rglob(".*.tmp"):
            match = _TEMP.fullmatch(path.name)
            if not match:
                continue
            with contextlib.suppress(OSError):
                lock = path.with_name(f".{match['target']}.lock")
                if now - path.stat().st_mtime > STALE_TEMP_SECONDS or _stale_lock_there(lock):
                    path.unlink()


def _stale_lock_there(lock: Path) -> bool:
    try:
        age = time.time() - os.stat(lock).st_mtime
    except OSError:
        return False  # no lock: an old temporary file goes by its age only
    return _is_stale(_read_owner(lock), age)
