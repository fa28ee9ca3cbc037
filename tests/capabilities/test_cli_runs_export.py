"""`costar runs export`: a run record as BehaviorTree.CPP's FileLogger2 (.btlog) and
SqliteLogger write a run, read back here by readers written from those formats' sources
(src/loggers/bt_file_logger_v2.cpp, bt_sqlite_logger.cpp), with every transition of the run.
"""

from __future__ import annotations

import io
import itertools
import sqlite3
import struct
import xml.etree.ElementTree as ET
from datetime import UTC, datetime
from pathlib import Path

import pytest

from capabilities.cli import main
from engine.trace import read_trace

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


def _cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


def _read_btlog(path: Path) -> tuple[str, int, list[tuple[int, int, int]]]:
    """(XML, start in microseconds, [(microseconds since the start, uid, status)])."""
    data = path.read_bytes()
    magic = b"BTCPP4-FileLogger2"
    assert data.startswith(magic) and data[len(magic)] == 1  # the protocol byte
    at = len(magic) + 1
    (length,) = struct.unpack_from("<i", data, at)
    xml = data[at + 4 : at + 4 + length].decode("utf-8")
    at += 4 + length
    (start,) = struct.unpack_from("<q", data, at)
    at += 8
    rest = data[at:]
    assert len(rest) % 9 == 0
    changes = []
    for i in range(0, len(rest), 9):
        usec = int.from_bytes(rest[i : i + 6], "little")
        uid, status = struct.unpack_from("<HB", rest, i + 6)
        changes.append((usec, uid, status))
    return xml, start, changes


def _uids(xml: str) -> set[int]:
    return {int(n.get("_uid", "0")) for n in ET.fromstring(xml).iter() if n.get("_uid")}


@pytest.mark.parametrize("example", ["figure3_debug", "nodes/subtree"])
def test_a_record_exports_to_a_btlog_and_sqlite_with_every_transition(
    tmp_path: Path, example: str
) -> None:
    runs = tmp_path / "runs"
    plan = str(EXAMPLES / f"{example}.costar.json")
    assert _cli("run", "--cell", "none", plan, "--rate", "200", "--runs", str(runs))[0] in (0, 1)
    record = read_trace(next(runs.iterdir()))
    btlog, db = tmp_path / "run.btlog", tmp_path / "run.db3"
    code, out, err = _cli("runs", "export", "last", "--runs", str(runs), "--btlog", str(btlog),
                          "--sqlite", str(db))  # fmt: skip
    assert code == 0, err
    xml, start, changes = _read_btlog(btlog)
    uids = _uids(xml)
    assert uids == set(range(1, len(uids) + 1))  # every node numbered from 1
    # Every status change of a node BehaviorTree.CPP has (all but our root) is there, in order.
    statuses = {"IDLE": 0, "RUNNING": 1, "SUCCESS": 2, "FAILURE": 3, "SKIPPED": 4}
    mine = [
        statuses[e["new"]] for e in record.events if e["event"] == "status" and e["node"] != "root"
    ]
    assert [status for _, _, status in changes] == mine
    assert {uid for _, uid, _ in changes} <= uids
    assert [u for u, _, _ in changes] == sorted(u for u, _, _ in changes)
    assert start == record.header["started_us"]
    assert f"{len(changes)} transitions" in out

    with sqlite3.connect(db) as data:
        (session, date, tree) = data.execute("SELECT * FROM Definitions").fetchone()
        assert tree == xml and session == 1
        day = datetime.strptime(date, "%Y-%m-%d %H:%M:%S").replace(tzinfo=UTC)  # UTC
        assert abs(day.timestamp() - start / 1e6) < 1.0
        nodes = data.execute("SELECT node_uid, fullpath FROM Nodes WHERE session_id = 1").fetchall()
        assert {uid for uid, _ in nodes} == uids
        rows = data.execute(
            "SELECT timestamp, node_uid, duration, state, extra_data FROM Transitions "
            "WHERE session_id = 1 ORDER BY timestamp"
        ).fetchall()
    assert [(uid, state) for _, uid, _, state, _ in rows] == [(u, s) for _, u, s in changes]
    assert all(b > a for (a, *_), (b, *_) in itertools.pairwise(rows))
    assert all(row[0] >= start for row in rows)
    failed = [extra for *_, state, extra in rows if state == 3]
    if example == "figure3_debug":  # its cup is not found twice before it is
        assert failed and all('"message"' in extra and '"error"' in extra for extra in failed)
        ended = [duration for _, _, duration, state, _ in rows if state in (2, 3)]
        assert any(duration > 0 for duration in ended)  # time RUNNING before a result


def test_an_export_without_a_file_to_write_or_of_a_record_that_is_not_says_why(
    tmp_path: Path,
) -> None:
    code, _, err = _cli("runs", "export", "last", "--runs", str(tmp_path))
    assert code == 2 and "--btlog FILE and/or --sqlite FILE" in err
    code, _, err = _cli("runs", "export", "last", "--runs", str(tmp_path), "--btlog", "x.btlog")
    assert code == 2 and "only 0 run records" in err
    runs = tmp_path / "runs"
    _cli(
        "run",
        "--cell",
        "none",
        str(EXAMPLES / "nodes" / "sequence.costar.json"),
        "--runs",
        str(runs),
    )
    code, _, err = _cli(
        "runs", "export", "last", "--runs", str(runs), "--btlog", str(tmp_path / "x.log")
    )
    assert code == 2 and "expected a name ending in .btlog" in err
