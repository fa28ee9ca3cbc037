"""bench/cli.py keeps its shape: one run of each command and the peer gives one JSON object
with wall time, CPU time, peak memory, ratios and the goal's verdicts (figures not asserted).
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_one_run_of_each_command_prints_figures_and_ratios(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    bench = importlib.import_module("bench.cli")
    assert bench.main(["--runs", "1", "--json"]) == 0
    fig = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert fig["runs"] == 1 and fig["goal"] == {"wall_s": 0.5, "rss_mb": 120.0}
    names = {"python -c pass", "validate --cell none", "import-xml", "export-xml", "examples",
             "ops --cell none", "trace show"}  # fmt: skip
    assert set(fig["commands"]) == names
    for name, row in fig["commands"].items():
        assert row["wall_s"] > 0 and row["cpu_s"] >= 0 and row["rss_mb"] > 0
        assert {"wall_ratio", "cpu_ratio", "rss_ratio"} <= set(row)
        assert ("meets_goal" in row) == (name != "python -c pass")
