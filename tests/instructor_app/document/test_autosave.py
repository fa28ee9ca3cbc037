"""Autosave: the dirty plan is written to the recovery folder and removed on save; what a
killed session left is found and restored.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pytest

from instructor_app.document.autosave import (
    Autosaver,
    Recovery,
    find_recoveries,
    offer_recoveries,
)
from instructor_app.document.editing import PlanDocument


@pytest.fixture
def document(qapp: Any, figure3_path: Path) -> PlanDocument:
    doc = PlanDocument()
    doc.open(figure3_path)
    return doc


def rename_root(document: PlanDocument, name: str = "edited") -> None:
    assert document.plan.tree is not None
    document.rename(document.plan.tree.id, name)


def test_nothing_is_written_while_the_document_is_clean(
    document: PlanDocument, recovery_dir: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=10)
    assert saver.write_now() is None
    assert list(recovery_dir.iterdir()) == []


def test_the_timer_writes_the_dirty_plan_with_a_sidecar(
    qtbot: Any, document: PlanDocument, recovery_dir: Path, figure3_path: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=20)
    rename_root(document)
    with qtbot.waitSignal(saver.written, timeout=2000):
        pass
    assert saver.plan_file.read_text(encoding="utf-8") == document.serialized()
    sidecar = json.loads(saver.sidecar.read_text(encoding="utf-8"))
    assert sidecar["original"] == str(figure3_path) and sidecar["pid"] == os.getpid()
    assert sorted(p.name for p in recovery_dir.iterdir()) == sorted(
        [saver.plan_file.name, saver.sidecar.name]
    )  # no temporary files left behind


def test_saving_removes_the_recovery_copy(
    document: PlanDocument, recovery_dir: Path, tmp_path: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    assert saver.write_now() == saver.plan_file
    document.save(tmp_path / "saved.costar.json")
    assert not saver.plan_file.exists() and not saver.sidecar.exists()


def test_undo_back_to_clean_and_stop_remove_the_copy(
    document: PlanDocument, recovery_dir: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    saver.write_now()
    document.undo_stack.undo()
    assert not saver.plan_file.exists()
    rename_root(document)
    saver.write_now()
    saver.stop()
    assert list(recovery_dir.iterdir()) == []


def test_find_recoveries_skips_its_own_and_broken_files(
    document: PlanDocument, recovery_dir: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    saver.write_now()
    (recovery_dir / "junk.recovery.json").write_text("{not json", encoding="utf-8")
    (recovery_dir / "junk.costar.json").write_text("{}", encoding="utf-8")
    (recovery_dir / "orphan.recovery.json").write_text("{}", encoding="utf-8")
    assert find_recoveries(recovery_dir, exclude={saver.plan_file}) == []
    found = find_recoveries(recovery_dir)
    assert [r.plan_file for r in found] == [saver.plan_file]
    assert found[0].name == document.plan.name and "autosaved" in found[0].describe()


def test_a_killed_session_is_restored_with_its_edits(
    qapp: Any, document: PlanDocument, recovery_dir: Path, figure3_path: Path
) -> None:
    # The first session edits and autosaves, then "dies": nothing cleans up after it.
    first = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document, "edited before the crash")
    first.write_now()
    edited = document.serialized()
    # The next session finds it, restores it dirty and under its original path.
    fresh = PlanDocument()
    second = Autosaver(fresh, recovery_dir, interval_ms=60_000)
    asked: list[str] = []
    restored = offer_recoveries(fresh, second, lambda text: asked.append(text) or True, _fail)
    assert isinstance(restored, Recovery) and len(asked) == 1
    assert fresh.serialized() == edited and fresh.dirty
    assert fresh.path == figure3_path
    assert not first.plan_file.exists()  # taken over by the second session's autosaver
    assert second.plan_file.exists()


def test_a_declined_recovery_is_deleted(
    qapp: Any, document: PlanDocument, recovery_dir: Path
) -> None:
    first = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    first.write_now()
    fresh = PlanDocument()
    second = Autosaver(fresh, recovery_dir, interval_ms=60_000)
    assert offer_recoveries(fresh, second, lambda text: False, _fail) is None
    assert list(recovery_dir.iterdir()) == [] and not fresh.dirty


def test_a_recovery_of_another_running_instance_is_not_offered(
    document: PlanDocument, recovery_dir: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    saver.write_now()
    data = json.loads(saver.sidecar.read_text(encoding="utf-8"))
    data["pid"] = os.getppid()  # a live process that is not this one
    saver.sidecar.write_text(json.dumps(data), encoding="utf-8")
    assert find_recoveries(recovery_dir) == []


def _fail(text: str) -> None:
    raise AssertionError(text)


@pytest.mark.parametrize("pid", [None, "12", True, 1e300])
def test_a_sidecar_with_an_odd_pid_is_offered_not_a_crash(
    document: PlanDocument, recovery_dir: Path, pid: object
) -> None:
    """The sidecar is read with the one JSON reader: a pid that is no process id (null, a
    text, ...) is nobody's, so its plan is offered; it used to raise a TypeError at start-up.
    """
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    saver.write_now()
    data = json.loads(saver.sidecar.read_text(encoding="utf-8"))
    data["pid"] = pid
    saver.sidecar.write_text(json.dumps(data), encoding="utf-8")
    assert [r.plan_file for r in find_recoveries(recovery_dir)] == [saver.plan_file]


def test_a_sidecar_of_another_format_or_a_bad_time_is_skipped(
    document: PlanDocument, recovery_dir: Path
) -> None:
    saver = Autosaver(document, recovery_dir, interval_ms=60_000)
    rename_root(document)
    saver.write_now()
    data = json.loads(saver.sidecar.read_text(encoding="utf-8"))
    saver.sidecar.write_text(json.dumps({**data, "saved_at": "noon"}), encoding="utf-8")
    assert find_recoveries(recovery_dir) == []
    saver.sidecar.write_text(json.dumps({**data, "format": "other"}), encoding="utf-8")
    assert find_recoveries(recovery_dir) == []
