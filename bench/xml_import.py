"""``costar import-xml`` on large files of short text lines: time and peak memory, against
expat alone reading the same file (the peer) in the same run.

The file is the XML export of ``example:nodes/action`` with port descriptions of many short
lines in its TreeNodesModel (as long comments pasted in Groot2 would be), each under the
import's limit of characters per element (``MAX_VALUE_CHARS``, 1 M): the tree is tiny, so the
figures are what reading the text costs. Each size is imported in a fresh
process (``costar import-xml``'s own code path, in-process ``capabilities.cli.main``), so its
peak resident memory is its own.

Figures, per size (``1.2MB``, ``19MB``; the import refuses files over 20 MB):

- ``bytes``: the file's size.
- ``import_s``: the time ``main(["import-xml", ...])`` took (after Python has started).
- ``expat_s``: a bare expat parse of the same file, no handlers: the peer.
- ``ratio``: import_s / expat_s (constant across sizes when the import is linear).
- ``peak_rss_mb``: the import process's peak resident memory; ``warm_rss_mb`` the peak
  before the big file (Python, the capabilities and a tiny import): the difference is what
  the file cost.
- ``exit``: the import's exit code (0: the plan was written).

Run from the repository root::

    .venv/bin/python bench/xml_import.py [--json] [--sizes 1.2,19]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

__all__ = ["main", "measure", "write_short_lines"]

ROOT = Path(__file__).resolve().parents[1]
LINE = "a short line of a long port description\n"

# Runs in a fresh interpreter: argv = xml file, plan file, a tiny xml file. Prints one JSON
# object. The tiny file is imported first, untimed: finding the installed capabilities
# (seconds, once per process) is not what is measured.
_CHILD = """
import io, json, resource, sys, time, xml.parsers.expat
from capabilities.cli import main
xml_file, plan_file, tiny = sys.argv[1], sys.argv[2], sys.argv[3]
main(["import-xml", tiny, plan_file], io.StringIO(), io.StringIO())
warm_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
with open(xml_file, "rb") as handle:
    xml.parsers.expat.ParserCreate().ParseFile(handle)
expat_s = time.perf_counter() - start
out, err = io.StringIO(), io.StringIO()
start = time.perf_counter()
code = main(["import-xml", xml_file, plan_file], out, err)
import_s = time.perf_counter() - start
rss_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"import_s": import_s, "expat_s": expat_s, "exit": code,
                  "peak_rss_mb": rss_kb / 1024, "warm_rss_mb": warm_kb / 1024,
                  "err": err.getvalue()[:300]}))
"""


def write_short_lines(path: Path, size: int) -> None:
    """An importable XML file of about ``size`` bytes, nearly all short text lines."""
    head = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<root BTCPP_format="4" main_tree_to_execute="Action">\n'
        '  <BehaviorTree ID="Action">\n'
        '    <debug__running name="move" then="SUCCESS" ticks="3.0"/>\n'
        "  </BehaviorTree>\n"
        "  <TreeNodesModel>\n"
    )
    tail = "  </TreeNodesModel>\n</root>\n"
    per_port = 20_000  # lines: 0.8 MB of text in one element
    lines, written = max(0, (size - len(head) - len(tail)) // len(LINE)), 0
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(head)
        while written < lines:
            count = min(per_port, lines - written)
            # a model of its own per description: unused, as in a library of node models
            handle.write(f'    <Action ID="notes_{written}"><input_port name="text">\n')
            for _ in range(count // 1000):
                handle.write(LINE * 1000)
            handle.write(LINE * (count % 1000))
            handle.write("</input_port></Action>\n")
            written += count
        handle.write(tail)


def measure(size_mb: float, folder: Path, timeout: float) -> dict[str, Any]:
    """Write a file of ``size_mb`` MB (10**6 bytes) and import it in a fresh process."""
    xml_file, plan_file = folder / f"lines_{size_mb}.xml", folder / "out.costar.json"
    write_short_lines(xml_file, int(size_mb * 1_000_000))
    tiny = folder / "tiny.xml"
    write_short_lines(tiny, 0)
    command = [sys.executable, "-c", _CHILD, str(xml_file), str(plan_file), str(tiny)]
    try:
        done = subprocess.run(
            command, cwd=ROOT, capture_output=True, text=True, timeout=timeout, check=False
        )
    except subprocess.TimeoutExpired:
        return {"bytes": xml_file.stat().st_size, "timed_out_after_s": timeout}
    if done.returncode != 0:
        return {"bytes": xml_file.stat().st_size, "failed": done.stderr[-500:]}
    figures: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    figures["bytes"] = xml_file.stat().st_size
    figures["ratio"] = figures["import_s"] / figures["expat_s"] if figures["expat_s"] else None
    return figures


def main(argv: list[str] | None = None) -> int:
    """Measure every size; print a table, or one JSON object with ``--json``."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--sizes", default="1.2,19", help="file sizes in MB, comma separated")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per import")
    args = parser.parse_args(argv)
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for size in (float(s) for s in args.sizes.split(",")):
            results[f"{size:g}MB"] = figures = measure(size, Path(tmp), args.timeout)
            if not args.json:
                print(f"{size:g} MB: {json.dumps(figures)}")
    if args.json:
        print(json.dumps(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
