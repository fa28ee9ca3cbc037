"""bench/soak.py keeps its shape: a very short soak prints one JSON object with memory
samples and growth, stalls, tick figures and Table I's counters (figures not asserted).
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_a_short_soak_prints_memory_stalls_and_ticks(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    soak = importlib.import_module("bench.soak")
    argv = ["--hours", "0.004", "--plan", "paper", "--sample-s", "1", "--seed", "901", "--json"]
    assert soak.main(argv) == 0
    fig = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert fig["plan"] == "paper" and fig["hours"] == 0.004
    assert fig["sim_s"] >= 0.004 * 3600
    assert set(fig["rss_mb"]) == {"first", "warm", "end", "max"}
    assert isinstance(fig["growth_pct"], float) and len(fig["samples"]) >= 2
    assert fig["stalls"] == [] and fig["stall_bound_s"] == 30.0
    assert fig["ticks"] > 0 and fig["tick_period_ms"] == 20.0
    assert 0 <= fig["overruns"] <= fig["ticks"] and 0 <= fig["late_ticks"] <= fig["ticks"]
    assert {"produced", "caught", "picks_per_hour"} <= set(fig["counters"])


def test_the_soak_scene_has_parts_for_the_hours(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    soak = importlib.import_module("bench.soak")
    data = json.loads(soak.soak_scene(tmp_path, 4.0).read_text(encoding="utf-8"))
    assert data["bender"]["parts"] == 1109  # 4 h of 13 s intervals (20 s - 35 %), and one
