"""Run records: the runs folder, record names that sort by start, pruning, finding, listing."""

from __future__ import annotations

import json
import os
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pytest

from engine.run_records import (
    RUNS_ENV,
    RunRecordError,
    find_record,
    list_records,
    new_record_path,
    prune_records,
    runs_folder,
)
from engine.trace import read_trace

START = datetime(2026, 11, 28, 1, 45, 12, tzinfo=UTC)


def _record(folder: Path, plan: str, minutes: int, lines: list[dict[str, object]]) -> Path:
    path = new_record_path(folder, plan, START + timedelta(minutes=minutes))
    header = {"format": "costar-trace", "format_version": 1, "plan": plan}
    path.write_text("".join(json.dumps(r) + "\n" for r in [header, *lines]), encoding="utf-8")
    return path


FINISHED = {"event": "finished", "tick": 42, "time": 1.0, "status": "SUCCESS", "reason": "finished"}


def test_the_folder_is_the_option_else_the_variable_else_the_setting_else_the_users(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv(RUNS_ENV, str(tmp_path / "env"))
    assert runs_folder(str(tmp_path / "opt"), "set") == tmp_path / "opt"
    assert runs_folder(None, "set") == tmp_path / "env"
    monkeypatch.delenv(RUNS_ENV)
    assert runs_folder(None, str(tmp_path / "set")) == tmp_path / "set"
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert runs_folder() == tmp_path / "data" / "costar" / "runs"


def test_names_sort_by_start_and_name_the_plan(tmp_path: Path) -> None:
    later = new_record_path(
        tmp_path / "runs", "Cup to bin (Figure 3)", START + timedelta(seconds=1)
    )
    first = new_record_path(tmp_path / "runs", "Cup to bin (Figure 3)", START)
    assert first.name == "20261128-014512-000000_cup-to-bin-figure-3.trace.jsonl"
    assert sorted([later, first]) == [first, later]
    first.touch()
    assert new_record_path(tmp_path / "runs", "Cup to bin (Figure 3)", START) != first


def test_the_oldest_records_go_past_the_limit_but_never_the_one_being_written(
    tmp_path: Path,
) -> None:
    paths = [_record(tmp_path, "p", m, [FINISHED]) for m in range(5)]
    size = paths[0].stat().st_size
    removed = prune_records(tmp_path, limit_bytes=2 * size, keep=paths[0])
    assert removed == paths[1:4]
    assert sorted(tmp_path.iterdir()) == [paths[0], paths[4]]


def test_records_are_listed_newest_first_with_how_their_run_ended(tmp_path: Path) -> None:
    done = _record(tmp_path, "kitting", 0, [FINISHED])
    stopped = {**FINISHED, "status": "RUNNING", "reason": "stopped", "tick": 7}
    halted = _record(tmp_path, "tending", 1, [stopped])
    killed = _record(tmp_path, "cup", 2, [{"event": "status", "tick": 1}])
    summaries = list_records(tmp_path)
    assert [s.path for s in summaries] == [killed, halted, done]
    assert [s.ended for s in summaries] == [
        "cut short (no end recorded)",
        "RUNNING after 7 ticks (stopped)",
        "SUCCESS after 42 ticks",
    ]
    assert summaries[2].plan == "kitting" and summaries[2].started == "2026-11-28 01:45:12"
    assert summaries[2].line().startswith("2026-11-28 01:45:12  kitting: SUCCESS after 42 ticks")


def test_a_record_is_found_by_path_name_start_or_last(tmp_path: Path) -> None:
    old = _record(tmp_path, "a", 0, [FINISHED])
    new = _record(tmp_path, "b", 1, [FINISHED])
    assert find_record(tmp_path, str(old)) == old
    assert find_record(tmp_path, new.name) == new
    assert find_record(tmp_path, "20261128-0146") == new
    assert find_record(tmp_path, "last") == new and find_record(tmp_path, "last-1") == old
    with pytest.raises(RunRecordError, match=r"2 run records .* start so"):
        find_record(tmp_path, "20261128")
    with pytest.raises(RunRecordError, match="no run record"):
        find_record(tmp_path, "1999")
    with pytest.raises(RunRecordError, match="only 2 run records"):
        find_record(tmp_path, "last-2")


def test_a_record_cut_in_the_middle_of_its_last_line_reads_up_to_it(tmp_path: Path) -> None:
    path = _record(tmp_path, "p", 0, [{"event": "status", "tick": 1, "time": 0.0}])
    with path.open("a", encoding="utf-8") as data:
        data.write('{"event": "status", "tick": 2, "ti')  # killed while writing this one
    trace = read_trace(path)
    assert [e["tick"] for e in trace.events] == [1]
    os.truncate(path, path.stat().st_size - 3)  # a broken line that is not the last is wrong
    with path.open("a", encoding="utf-8") as data:
        data.write("\n" + json.dumps(FINISHED) + "\n")
    with pytest.raises(Exception, match=r":3"):
        read_trace(path)
