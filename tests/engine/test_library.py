"""The subtree library folder: files round-trip, broken files are skipped, no lost update."""

from __future__ import annotations

import multiprocessing
from pathlib import Path

import pytest
from test_subtrees import pick_subtree

from engine.library import (
    LIBRARY_ENV,
    Library,
    LibraryConflict,
    dump_subtree,
    library_folder,
    load_subtree,
)


def test_save_and_load_round_trip_byte_for_byte(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    saved = library.save(pick_subtree(), "kitting/plates")
    assert saved.version == 1 and saved.date.endswith("Z")
    path = tmp_path / "kitting" / "plates" / "Pick.subtree.json"
    assert load_subtree(path) == saved
    assert dump_subtree(load_subtree(path)) == path.read_text(encoding="utf-8")
    again = Library(tmp_path, shipped=()).scan()
    assert again.folders() == ["kitting/plates"] and again.latest("test.pick") == saved


def test_a_new_version_needs_the_version_it_started_from(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    first = library.save(pick_subtree())
    library.scan()
    second = library.save(first, base_version=1)
    assert second.version == 2
    with pytest.raises(LibraryConflict, match="saved by someone else \\(version 2\\)"):
        library.save(first, base_version=1)
    with pytest.raises(LibraryConflict, match="already in the library"):
        Library(tmp_path, shipped=()).save(pick_subtree())


def test_malformed_file_is_named_and_skipped(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    library.save(pick_subtree())
    (tmp_path / "broken.subtree.json").write_text('{"format": "costar-subtree", "format_v')
    (tmp_path / "odd.subtree.json").write_text('{"format": "costar-subtree", "format_version": 1}')
    library.scan()
    assert [e.subtree.name for e in library.entries] == ["Pick"]
    assert len(library.problems) == 2
    assert any("broken.subtree.json" in p and "line 1" in p for p in library.problems)
    assert any("odd.subtree.json" in p and "$" in p for p in library.problems)


def test_location_option_beats_environment_beats_setting(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(LIBRARY_ENV, str(tmp_path / "env"))
    assert library_folder("opt", "set") == Path("opt")
    assert library_folder(None, "set") == tmp_path / "env"
    monkeypatch.delenv(LIBRARY_ENV)
    assert library_folder(None, "set") == Path("set")
    assert library_folder().name == "library"


def test_search_finds_by_name_description_and_ports(tmp_path: Path) -> None:
    library = Library(tmp_path, shipped=()).scan()
    library.save(pick_subtree(), "kitting")
    library.scan()
    assert [e.subtree.name for e in library.search("finds object")] == ["Pick"]
    assert [e.subtree.name for e in library.search("kitting result")] == ["Pick"]
    assert library.search("holster") == []


def _writer(folder: str, who: str, count: int) -> None:
    """One Instructor: saves its own subtrees and updates a common one, retrying conflicts."""
    library = Library(Path(folder), shipped=())
    for index in range(count):
        sub = pick_subtree()
        sub.id, sub.name = f"{who}.{index}", f"{who} {index}"
        library.scan().save(sub, who)
        while True:  # a read-modify-write of the common subtree, as an editor does
            current = library.scan().latest("common")
            assert current is not None
            current.description += f"{who}{index};"
            try:
                library.save(current, base_version=current.version)
                break
            except LibraryConflict:
                continue


def test_two_processes_writing_at_once_lose_nothing(tmp_path: Path) -> None:
    common = pick_subtree()
    common.id, common.name, common.description = "common", "Common", ""
    Library(tmp_path, shipped=()).scan().save(common)
    count = 12
    context = multiprocessing.get_context("spawn")
    workers = [
        context.Process(target=_writer, args=(str(tmp_path), who, count)) for who in ("a", "b")
    ]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(60)
        assert worker.exitcode == 0
    library = Library(tmp_path, shipped=()).scan()
    assert library.problems == []
    assert len(library.entries) == 1 + 2 * count
    final = library.latest("common")
    assert final is not None and final.version == 1 + 2 * count
    updates = set(final.description.rstrip(";").split(";"))
    assert updates == {f"{who}{i}" for who in "ab" for i in range(count)}
    assert not list(tmp_path.rglob(".*.lock")) and not list(tmp_path.rglob(".*.tmp"))


def test_a_changed_shipped_subtree_is_saved_to_the_writable_folder(tmp_path: Path) -> None:
    shipped = tmp_path / "shipped"
    Library(shipped, shipped=()).scan().save(pick_subtree(), "kitting")
    library = Library(tmp_path / "mine", shipped=(shipped,)).scan()
    original = library.latest("test.pick")
    assert original is not None and library.entry("test.pick").shipped  # type: ignore[union-attr]
    original.description = "mine now"
    saved = library.save(original, base_version=original.version)
    assert saved.version == 2 and (tmp_path / "mine" / "kitting" / "Pick.subtree.json").exists()
    library.scan()
    assert library.latest("test.pick") == saved and not library.entry("test.pick").shipped  # type: ignore[union-attr]
