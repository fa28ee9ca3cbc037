"""A run record as BehaviorTree.CPP's loggers write a run: ``.btlog`` and SQLite.

Both start from the tree as BehaviorTree.CPP holds it once loaded (:mod:`engine.btcpp.runtime`:
the XML with a ``_uid`` on every node) and list the record's status changes by those uids.
Our root node has no counterpart there: its changes are left out, as are nodes the loaded
tree does not have.

- FileLogger2 (``src/loggers/bt_file_logger_v2.cpp``): the text ``BTCPP4-FileLogger2``, a
  protocol byte 1, the XML's length as a little-endian int32, the XML, the start as an int64
  of microseconds since the epoch, then one 9-byte transition per change: 6 bytes of
  microseconds since the start, the uid as 2 bytes, the status as 1 byte (little-endian).
- SqliteLogger (``src/loggers/bt_sqlite_logger.cpp``): tables ``Definitions`` (session_id,
  date, xml_tree), ``Nodes`` (session_id, fullpath, node_uid) and ``Transitions`` (timestamp
  in microseconds since the epoch, made strictly increasing; session_id; node_uid; duration:
  microseconds RUNNING when a node leaves RUNNING, else 0; state; extra_data: here the
  error type and message of a failure, as JSON).

Status numbers are BehaviorTree.CPP's: IDLE 0, RUNNING 1, SUCCESS 2, FAILURE 3, SKIPPED 4.
"""

from __future__ import annotations

import json
import sqlite3
import struct
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from engine.btcpp.errors import XmlExportError
from engine.btcpp.runtime import LoadedTree

__all__ = [
    "BTLOG_MAGIC",
    "STATUS_CODES",
    "Transition",
    "transitions",
    "write_btlog",
    "write_sqlite",
]

BTLOG_MAGIC = b"BTCPP4-FileLogger2"
STATUS_CODES = {"IDLE": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3, "SKIPPED": 4}
_MAX_USEC = (1 << 48) - 1  # the .btlog's 6 bytes of time


@dataclass(frozen=True)
class Transition:
    """One status change by uid: microseconds since the run's start, old and new status."""

    usec: int
    uid: int
    old: int
    new: int
    extra: str  # the failure's error type and message (JSON), else ""


def transitions(events: list[dict[str, Any]], uids: Mapping[str, int]) -> Iterator[Transition]:
    """The record's status changes (its ``status`` events) as loaded-tree transitions."""
    start: float | None = None
    for event in events:
        if start is None and "time" in event:
            start = float(event["time"])
        if event.get("event") != "status" or event.get("node") not in uids:
            continue
        assert start is not None
        usec = max(0, round((float(event["time"]) - start) * 1e6))
        extra = ""
        if event.get("new") == "FAILURE":
            extra = json.dumps(
                {"error": event.get("error", ""), "message": event.get("message", "")}
            )
        yield Transition(
            usec,
            uids[event["node"]],
            STATUS_CODES.get(str(event.get("old")), 0),
            STATUS_CODES.get(str(event.get("new")), 0),
            extra,
        )


def write_btlog(path: Path, loaded: LoadedTree, started_us: int, changes: list[Transition]) -> None:
    """Write a FileLogger2 file (``*.btlog``)."""
    if path.suffix != ".btlog":
        got = repr(path.suffix or "no extension")
        raise XmlExportError(str(path), "its name", "a name ending in .btlog (FileLogger2)", got)
    xml = loaded.xml.encode("utf-8")
    parts = [
        BTLOG_MAGIC,
        bytes([1]),
        struct.pack("<i", len(xml)),
        xml,
        struct.pack("<q", started_us),
    ]
    for change in changes:
        parts.append(struct.pack("<Q", min(change.usec, _MAX_USEC))[:6])
        parts.append(struct.pack("<HB", change.uid, change.new))
    path.write_bytes(b"".join(parts))


def _full_paths(xml: str) -> Iterator[tuple[str, int]]:
    """(fullpath, uid) of every node of a loaded tree, as BehaviorTree.CPP names them: the
    instance's path and "/", the node's name, and "::uid" when its name is its type.
    """
    for tree in ET.fromstring(xml).iter("BehaviorTree"):
        prefix = tree.get("_fullpath", "")
        prefix = f"{prefix}/" if prefix else ""
        for node in tree.iter():
            uid = node.get("_uid")
            if node is tree or uid is None:
                continue
            name = node.get("name") or node.tag
            yield prefix + name + (f"::{uid}" if name == node.tag else ""), int(uid)


def write_sqlite(
    path: Path, loaded: LoadedTree, started_us: int, changes: list[Transition]
) -> None:
    """Write (a new) SqliteLogger database (``*.db3`` or ``*.btdb``)."""
    if path.suffix not in (".db3", ".btdb"):
        got = repr(path.suffix or "no extension")
        raise XmlExportError(str(path), "its name", "a name ending in .db3 or .btdb", got)
    path.unlink(missing_ok=True)
    date = datetime.fromtimestamp(started_us / 1e6, UTC).strftime("%Y-%m-%d %H:%M:%S")
    with sqlite3.connect(path) as db:
        db.execute(
            "CREATE TABLE Transitions (timestamp INTEGER PRIMARY KEY NOT NULL, session_id "
            "INTEGER NOT NULL, node_uid INTEGER NOT NULL, duration INTEGER, state INTEGER "
            "NOT NULL, extra_data VARCHAR)"
        )
        db.execute(
            "CREATE TABLE Nodes (session_id INTEGER NOT NULL, fullpath VARCHAR, node_uid INTEGER NOT NULL)"
        )
        db.execute(
            "CREATE TABLE Definitions (session_id INTEGER PRIMARY KEY AUTOINCREMENT, date TEXT "
            "NOT NULL, xml_tree TEXT NOT NULL)"
        )
        session = db.execute(
            "INSERT INTO Definitions (date, xml_tree) VALUES (?, ?)", (date, loaded.xml)
        ).lastrowid
        db.executemany(
            "INSERT INTO Nodes VALUES (?, ?, ?)",
            [(session, full, uid) for full, uid in _full_paths(loaded.xml)],
        )
        rows, running_since, stamp = [], {}, 0
        for change in changes:
            stamp = max(stamp + 1, started_us + change.usec)  # the key must grow
            duration = 0
            if change.old == 0 and change.new == 1:
                running_since[change.uid] = stamp
            elif change.old == 1 and change.new != 1:
                duration = stamp - running_since.get(change.uid, stamp)
            rows.append((stamp, session, change.uid, duration, change.new, change.extra))
        db.executemany("INSERT INTO Transitions VALUES (?, ?, ?, ?, ?, ?)", rows)
