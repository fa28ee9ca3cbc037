"""The library stays in its folder, survives a writer killed mid-save, names files in any script.

Folders are relative and stay inside the library (absolute, drive, UNC, NUL, ``..`` and
symbolic links out are refused with :class:`LibraryError`); a lock left by a killed save is
broken at once and its temporary file removed; names in any script get distinct files.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from test_subtrees import pick_subtree

from engine.library import (
    STALE_LOCK_SECONDS,
    STALE_TEMP_SECONDS,
    Library,
    LibraryConflict,
    LibraryError,
    file_name,
    load_subtree,
)
from engine.spec import SubtreeSpec

REPO = Path(__file__).resolve().parents[2]


def _named(name: str, subtree_id: str | None = None) -> SubtreeSpec:
    sub = pick_subtree()
    sub.name, sub.id = name, subtree_id or f"test.{name}"
    return sub


def _files(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())


@pytest.mark.parametrize(
    "folder",
    [
        "/tmp/elsewhere",
        "C:\\x",
        "C:/x",
        "C:x",
        "\\\\server\\share",
        "//server/share",
        "\\rooted",
        "a\x00b",
        "tab\there",
        "..",
        "a/../../b",
        "a\\..\\..\\b",
        "kitting/..",
    ],
)
def test_a_folder_outside_the_library_is_refused_by_name(tmp_path: Path, folder: str) -> None:
    root = tmp_path / "library"
    library = Library(root, shipped=()).scan()
    with pytest.raises(LibraryError, match="expected a folder inside the library") as caught:
        library.save(pick_subtree(), folder)
    assert repr(folder) in str(caught.value)
    assert not isinstance(caught.value, LibraryConflict)
    assert _files(tmp_path) == []  # nothing written, inside the library or out


def test_an_existing_subtree_is_refused_a_bad_folder_too(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    first = library.save(pick_subtree())
    library.scan()
    with pytest.raises(LibraryError, match="absolute"):
        library.save(first, "/tmp", base_version=1)


def test_a_symbolic_link_out_of_the_library_is_refused(tmp_path: Path) -> None:
    root, elsewhere = tmp_path / "library", tmp_path / "elsewhere"
    (root / "real").mkdir(parents=True)
    elsewhere.mkdir()
    (root / "out").symlink_to(elsewhere, target_is_directory=True)
    (root / "in").symlink_to(root / "real", target_is_directory=True)
    library = Library(root, shipped=()).scan()
    for folder in ("out", "out/deeper", "./out"):
        with pytest.raises(LibraryError, match="leads out of the library"):
            library.save(pick_subtree(), folder)
    assert _files(elsewhere) == []
    saved = library.save(pick_subtree(), "in")  # a link that stays inside is a folder
    assert load_subtree(root / "real" / "Pick.subtree.json") == saved


def test_relative_folders_and_backslashes_stay_inside(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    library.save(_named("One"), "kitting\\plates")
    library.save(_named("Two"), "./kitting//plates/")
    assert _files(tmp_path) == [
        "kitting/plates/One.subtree.json",
        "kitting/plates/Two.subtree.json",
    ]


_KILLED_WRITER = """
import os, sys, time
from pathlib import Path
from engine.library import Library, load_subtree

def hang(source, target):  # the save's temporary file is written: die before the rename
    print("writing", flush=True)
    time.sleep(600)

os.replace = hang
Library(Path(sys.argv[1]), shipped=()).scan().save(load_subtree(sys.argv[2]))
"""


def test_a_save_after_kill_9_of_a_saving_process_succeeds_at_once(tmp_path: Path) -> None:
    root, source = tmp_path / "library", tmp_path / "source"
    Library(source, shipped=()).scan().save(pick_subtree())
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
    }
    writer = subprocess.Popen(
        [sys.executable, "-c", _KILLED_WRITER, str(root), str(source / "Pick.subtree.json")],
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    try:
        assert writer.stdout is not None and writer.stdout.readline() == "writing\n"
    finally:
        writer.send_signal(signal.SIGKILL)
        writer.wait(30)  # reaped: its PID is gone
    lock = root / ".Pick.subtree.json.lock"
    owner = json.loads(lock.read_text())
    assert owner["pid"] == writer.pid and owner["host"] and owner["started"] > 0
    assert len(list(root.glob(".Pick.subtree.json.*.tmp"))) == 1
    # a fresh lock: only its dead PID says it is stale (a short wait fails a regression fast)
    library = Library(root, shipped=(), lock_wait=0.2)  # not listed: the save cleans up
    saved = library.save(pick_subtree())
    assert saved.version == 1
    assert load_subtree(root / "Pick.subtree.json") == saved
    assert _files(root) == ["Pick.subtree.json"]  # the stale lock and the temporary file gone


def _lock(root: Path, name: str, content: str, age: float = 0.0) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    lock = root / f".{name}.lock"
    lock.write_text(content)
    if age:
        then = time.time() - age
        os.utime(lock, (then, then))
    return lock


def test_a_live_lock_of_another_host_is_waited_for_then_refused(tmp_path: Path) -> None:
    owner = {"pid": os.getpid(), "host": "another-host.invalid", "started": time.time()}
    lock = _lock(tmp_path, "Pick.subtree.json", json.dumps(owner))
    library = Library(tmp_path, shipped=(), lock_wait=0.05).scan()
    with pytest.raises(LibraryError, match=r"another Instructor is saving.*another-host\.invalid"):
        library.save(pick_subtree())
    assert lock.exists()
    os.utime(lock, (time.time() - 2 * STALE_LOCK_SECONDS,) * 2)  # its writer hung or died
    assert library.save(pick_subtree()).version == 1
    assert not lock.exists()


def test_a_live_lock_of_this_host_is_respected(tmp_path: Path) -> None:
    owner = {"pid": os.getpid(), "host": socket.gethostname(), "started": 0}
    lock = _lock(tmp_path, "Pick.subtree.json", json.dumps(owner))
    with pytest.raises(LibraryError, match="another Instructor is saving"):
        Library(tmp_path, shipped=(), lock_wait=0.05).scan().save(pick_subtree())
    assert lock.exists()


def test_an_unreadable_lock_is_broken_once_it_is_not_being_written(tmp_path: Path) -> None:
    lock = _lock(tmp_path, "Pick.subtree.json", "")  # a writer between creating and writing it
    library = Library(tmp_path, shipped=(), lock_wait=0.05).scan()
    with pytest.raises(LibraryError, match="an unknown writer"):
        library.save(pick_subtree())
    _lock(tmp_path, "Pick.subtree.json", "garbage\0", age=10.0)
    assert library.save(pick_subtree()).version == 1
    assert not lock.exists()


def test_an_earlier_instructors_lock_holds_its_pid_only(tmp_path: Path) -> None:
    lock = _lock(tmp_path, "Pick.subtree.json", f"{os.getpid()}\n")
    library = Library(tmp_path, shipped=(), lock_wait=0.05).scan()
    with pytest.raises(LibraryError, match=f"process {os.getpid()}"):
        library.save(pick_subtree())
    os.utime(lock, (time.time() - 2 * STALE_LOCK_SECONDS,) * 2)
    assert library.save(pick_subtree()).version == 1


def _dead_pid() -> int:
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait(30)
    return process.pid


def test_a_dead_writers_temporary_file_is_removed_when_the_library_is_listed(
    tmp_path: Path,
) -> None:
    owner = {"pid": _dead_pid(), "host": socket.gethostname(), "started": time.time()}
    lock = _lock(tmp_path, "Pick.subtree.json", json.dumps(owner))
    left = tmp_path / ".Pick.subtree.json.89abcdef.tmp"
    left.write_text("{")
    live = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time()}
    _lock(tmp_path, "Other.subtree.json", json.dumps(live))
    writing = tmp_path / ".Other.subtree.json.01234567.tmp"  # its writer is alive
    writing.write_text("{")
    library = Library(tmp_path, shipped=()).scan()
    assert not left.exists() and writing.exists() and library.problems == []
    assert library.save(pick_subtree()).version == 1 and not lock.exists()


def test_old_temporary_files_are_removed_when_the_library_is_listed(tmp_path: Path) -> None:
    Library(tmp_path, shipped=()).scan().save(pick_subtree(), "kitting")
    folder = tmp_path / "kitting"
    old = folder / ".Pick.subtree.json.0123abcd.tmp"
    fresh = folder / ".Pick.subtree.json.4567cdef.tmp"  # a save under way in another process
    other = folder / ".notes.tmp"  # not the library's
    for path in (old, fresh, other):
        path.write_text("{")
    then = time.time() - 2 * STALE_TEMP_SECONDS
    for path in (old, other):
        os.utime(path, (then, then))
    library = Library(tmp_path, shipped=()).scan()
    assert not old.exists() and fresh.exists() and other.exists()
    assert [e.subtree.name for e in library.entries] == ["Pick"] and library.problems == []


@pytest.mark.parametrize(
    ("first", "second"),
    [("名前", "名字"), ("Привет", "Пока"), ("नमस्ते", "नमस्कार"), ("🤖", "🦾"), ("!!!", "???")],
)
def test_names_in_any_script_get_distinct_files_and_round_trip(
    tmp_path: Path, first: str, second: str
) -> None:
    library = Library(tmp_path, shipped=()).scan()
    one, two = library.save(_named(first, "a")), library.save(_named(second, "b"))
    assert file_name(first) != file_name(second)
    assert len(_files(tmp_path)) == 2
    again = Library(tmp_path, shipped=()).scan()
    assert again.latest("a") == one and again.latest("b") == two
    assert {e.subtree.name for e in again.entries} == {first, second}


def test_file_names_keep_ascii_names_as_they_were_and_stay_short() -> None:
    assert file_name("Pick") == "Pick.subtree.json"
    assert file_name("Pick part / v2") == "Pick_part_v2.subtree.json"
    assert file_name("a _b") == "a__b.subtree.json"
    assert file_name(".hidden.") == "hidden.subtree.json"
    assert file_name("名前") == "名前.subtree.json"
    assert file_name("\uff46\uff55\uff4c\uff4c") == "full.subtree.json"  # NFKC: fullwidth
    assert file_name("a\u200bb") == "a_b.subtree.json"  # a zero-width space is not kept
    long_a, long_b = "名" * 200 + "a", "名" * 200 + "b"
    assert file_name(long_a) != file_name(long_b)
    assert all(len(f".{file_name(n)}.0123abcd.tmp".encode()) <= 255 for n in (long_a, long_b))


def test_the_same_unicode_name_twice_is_refused(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    library.save(_named("名前", "a"))
    library.scan()
    with pytest.raises(LibraryConflict, match="another subtree called '名前'"):
        library.save(_named("名前", "b"))
