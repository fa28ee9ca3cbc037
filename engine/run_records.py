"""Run records: every run's trace kept in one folder, the oldest removed past a size limit.

A run record is a trace (``engine.trace``: JSON lines, flushed event by event, so a killed
run leaves its record up to that moment) written to the runs folder under a name that sorts
by its start: ``20261128-014512-123456_cup-to-bin.trace.jsonl``. Where the folder is: the
``--runs`` option of a command, else ``$COSTAR_RUNS``, else the Instructor's setting, else
the user's data folder (``~/.local/share/costar/runs`` on Linux), as for the library.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from engine.errors import EngineError
from engine.library import chosen_folder, user_data_folder

__all__ = [
    "RUNS_ENV",
    "RecordSummary",
    "RunRecordError",
    "default_runs_folder",
    "find_record",
    "list_records",
    "new_record_path",
    "prune_records",
    "runs_folder",
]

RUNS_ENV = "COSTAR_RUNS"
RECORD_SUFFIX = ".trace.jsonl"
LIMIT_BYTES = 500 * 1024 * 1024  # the folder's size before the oldest records go
_TAIL_BYTES = 64 * 1024  # how much of a record's end is read for its summary


class RunRecordError(EngineError):
    """No such run record, or a runs folder that cannot be used."""


def default_runs_folder() -> Path:
    """The per-user runs folder (``~/.local/share/costar/runs`` on Linux)."""
    return user_data_folder("runs")


def runs_folder(option: str | None = None, setting: str | None = None) -> Path:
    """The runs folder: the option, else $COSTAR_RUNS, else the setting, else the user's."""
    return chosen_folder(option, RUNS_ENV, setting, "runs")


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")[:40] or "plan"


def new_record_path(folder: Path, plan_name: str, now: datetime | None = None) -> Path:
    """A fresh record's path in ``folder`` (made if missing), named by the time and plan."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunRecordError(f"{folder}: cannot make the runs folder: {exc}") from exc
    stamp = (now or datetime.now(UTC)).strftime("%Y%m%d-%H%M%S-%f")
    path = folder / f"{stamp}_{_slug(plan_name)}{RECORD_SUFFIX}"
    count = 1
    while path.exists():  # two runs in the same microsecond
        count += 1
        path = folder / f"{stamp}-{count}_{_slug(plan_name)}{RECORD_SUFFIX}"
    return path


def _records(folder: Path) -> list[Path]:
    """The folder's records, oldest first (their names sort by start)."""
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if p.name.endswith(RECORD_SUFFIX))


def prune_records(
    folder: Path, limit_bytes: int = LIMIT_BYTES, keep: Path | None = None
) -> list[Path]:
    """Remove the oldest records until the folder holds at most ``limit_bytes`` (never
    ``keep``, the record being written); returns the records removed.
    """
    records = _records(folder)
    sizes = {p: p.stat().st_size for p in records}
    total = sum(sizes.values())
    removed = []
    for path in records:
        if total <= limit_bytes:
            break
        if path == keep:
            continue
        try:
            path.unlink()
        except OSError:  # another process removed it, or it is not ours to remove
            continue
        total -= sizes[path]
        removed.append(path)
    return removed


@dataclass(frozen=True)
class RecordSummary:
    """One line of ``costar runs list``: a record, its plan and how its run ended."""

    path: Path
    plan: str
    started: str  # UTC, from the record's name: "2026-11-28 01:45:12"
    ended: str  # "SUCCESS after 321 ticks", or "cut short" when the record has no end
    size: int

    def line(self) -> str:
        kib = max(1, round(self.size / 1024))
        return f"{self.started}  {self.plan or '(unnamed plan)'}: {self.ended}  ({kib} KiB)  {self.path.name}"


def _summary(path: Path) -> RecordSummary:
    size = path.stat().st_size
    with path.open("rb") as data:
        first = data.readline()
        data.seek(max(0, size - _TAIL_BYTES))
        tail = data.read().decode("utf-8", "replace").splitlines()
    plan, ended = "", "cut short (no end recorded)"
    try:
        plan = str(json.loads(first).get("plan") or "")
    except (ValueError, AttributeError):
        plan = "(not a trace)"
    for line in reversed(tail):
        try:
            record = json.loads(line)
        except ValueError:
            continue
        if isinstance(record, dict) and record.get("event") == "finished":
            ended = f"{record.get('status')} after {record.get('tick')} ticks"
            reason = record.get("reason")
            if reason and reason != "finished":
                ended += f" ({reason})"
            break
    stamp = path.name.split("_", 1)[0]
    try:
        started = datetime.strptime(stamp[:15], "%Y%m%d-%H%M%S").strftime("%Y-%m-%d %H:%M:%S")
    except ValueError:
        started = stamp
    return RecordSummary(path, plan, started, ended, size)


def list_records(folder: Path) -> list[RecordSummary]:
    """The folder's records, newest first."""
    return [_summary(path) for path in reversed(_records(folder))]


def find_record(folder: Path, ref: str) -> Path:
    """A record by its path, its name (or the start of it) in ``folder``, or ``last``
    (the newest; ``last-1`` the one before).
    """
    given = Path(ref).expanduser()
    if given.is_file():
        return given
    records = _records(folder)
    if ref == "last" or ref.startswith("last-"):
        back = int(ref[5:]) if ref[5:].isdigit() else 0
        if back < len(records):
            return records[-1 - back]
        raise RunRecordError(f"{folder}: there are only {len(records)} run records")
    matches = [p for p in records if p.name.startswith(ref)]
    if len(matches) == 1:
        return matches[0]
    if not matches:
        raise RunRecordError(f"{ref}: no such file, and no run record in {folder} starts so")
    names = ", ".join(p.name for p in matches[:5])
    raise RunRecordError(f"{ref}: {len(matches)} run records in {folder} start so: {names}")
