"""bench/casestudies.py keeps its shape: one JSON object with tending (the paper's plan and
ours, Table I's counters), kitting and cup_to_bin, and Table I printed side by side. Tiny
runs (one part, one seed): the goals are the bench's to measure, not asserted here.
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path
from types import ModuleType

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
COUNTERS = {"produced", "caught", "scrapped", "bad_weld", "bad_grasp", "lost_to_stops",
            "operator_interventions", "picks_per_hour"}  # fmt: skip


@pytest.fixture(scope="module")
def casestudies() -> ModuleType:
    """``bench.casestudies``; ``bench/`` is not an installed package: import it from the repo."""
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(REPO_ROOT))
        return importlib.import_module("bench.casestudies")


def test_table_one_puts_the_paper_beside_both_plans(casestudies: ModuleType) -> None:
    tending = importlib.import_module("bench._tending")
    ours = {"produced": 100, "caught": 95, "scrapped": 5, "operator_interventions": 0}
    text = tending.table_one({"paper": {"skipped": "not run"}, "ours": ours})
    lines = {line.split()[0]: line.split()[1:] for line in text.splitlines()[1:]}
    assert lines["caught"] == ["82", "-", "95"]
    assert lines["lost_to_stops"] == ["13", "-", "-"]
    assert lines["handled"] == ["82", "%", "(93", "%", "proj.)", "-", "100", "%"]


def test_a_tiny_run_prints_one_json_object_of_every_case(
    casestudies: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    """One part of the paper's plan (ours is left out: its own tests run it), one seed of
    cup_to_bin.
    """
    argv = ["--only", "tending", "--only", "cup_to_bin", "--plan", "paper", "--parts", "1",
            "--trials", "1", "--runs", "1", "--first-seed", "20", "--seed", "900", "--json",
            "--record-parts", "0"]  # fmt: skip
    assert casestudies.main(argv) == 0
    figures = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert set(figures) == {"tending", "cup_to_bin"}
    paper = figures["tending"]["paper"]
    assert set(paper) >= COUNTERS and paper["produced"] == 1 and not paper["errors"]
    assert [t["seed"] for t in paper["trials"]] == [900]
    assert paper["caught"] + paper["lost"] == 1
    assert figures["tending"]["ours"] == {"skipped": "not asked for"}
    assert set(figures["cup_to_bin"]) == {"runs", "succeeded", "failures", "wall_s_per_run"}
    assert figures["cup_to_bin"]["runs"] == 1


def test_pairs_of_trials_give_each_figure_with_its_spread(casestudies: ModuleType) -> None:
    """Two pairs of trials (fake counters): each pair's Table I, each row's mean, minimum and
    maximum over the pairs, and the table prints them as mean (min-max).
    """
    tending = importlib.import_module("bench._tending")

    def trial(caught: int, lost: int) -> dict[str, object]:
        return {"produced": caught + lost, "caught": caught, "lost": lost, "sim_seconds": 900.0}

    trials = [trial(40, 10), trial(42, 8), trial(45, 5), trial(47, 3)]
    figures = tending._total(trials) | tending._spread(trials, 2)
    assert [p["caught"] for p in figures["pairs"]] == [82, 92]
    assert figures["spread"]["caught"] == {"mean": 87.0, "min": 82.0, "max": 92.0}
    assert figures["spread"]["produced"] == {"mean": 100.0, "min": 100.0, "max": 100.0}
    text = tending.table_one({"paper": figures, "ours": {"skipped": "not run"}})
    assert text.splitlines()[0].startswith("Table I, 2 pairs")
    caught = next(line for line in text.splitlines() if line.startswith("caught"))
    assert caught.split()[1:] == ["82", "87", "(82-92)", "-"]
