"""The engine-ticks benchmark builds the shared trees correctly in both engines.

Runs the bench's build + visit-count verification (never its timing) so that a regression
in tree building or in tick semantics (latching, memory, Parallel synchronisation, reset)
breaks the suite. Nothing here asserts a time.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
TREE_IDS = ("T1", "T2", "T3", "T4")
ENGINE_NAMES = ("ours", "py_trees")


@pytest.fixture(scope="module")
def ticks() -> ModuleType:
    """``bench.engine_ticks``; ``bench/`` is not an installed package: import it from the repo."""
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(REPO_ROOT))
        return importlib.import_module("bench.engine_ticks")


@pytest.fixture(scope="module")
def bench(ticks: ModuleType) -> ModuleType:
    """``bench._bt_trees``: the loader and the builders of both engines."""
    return importlib.import_module("bench._bt_trees")


@pytest.fixture(scope="module")
def trees(bench: ModuleType) -> dict[str, Any]:
    return {tree.id: tree for tree in bench.load_trees(bench.default_trees_path())}


def _builder(bench: ModuleType, engine: str) -> Callable[[Any], Any]:
    return dict(bench.ENGINES)[engine]


def test_the_file_holds_the_four_trees(trees: dict[str, Any]) -> None:
    assert tuple(trees) == TREE_IDS


@pytest.mark.parametrize("engine", ENGINE_NAMES)
@pytest.mark.parametrize("tree_id", TREE_IDS)
def test_built_tree_matches_the_expected_counts(
    ticks: ModuleType, bench: ModuleType, trees: dict[str, Any], tree_id: str, engine: str
) -> None:
    tree = trees[tree_id]
    ticks.verify(tree, _builder(bench, engine)(tree))  # raises BenchError on any mismatch


@pytest.mark.parametrize(
    ("tree_id", "field"),
    [("T1", "visits_per_tick"), ("T3", "node_count"), ("T4", "ticks_to_complete")],
)
def test_verification_fails_on_a_wrong_expectation(
    ticks: ModuleType, bench: ModuleType, trees: dict[str, Any], tree_id: str, field: str
) -> None:
    tree = trees[tree_id]
    wrong = dataclasses.replace(tree, expected={**tree.expected, field: tree.expected[field] + 1})
    with pytest.raises(bench.BenchError, match=tree_id):
        ticks.verify(wrong, _builder(bench, "ours")(wrong))


def test_our_per_tick_tree_latches_until_reset(bench: ModuleType, trees: dict[str, Any]) -> None:
    built = bench.build_ours(trees["T1"])
    assert built.tick_once() == "SUCCESS"
    leaf = built.nodes[1]
    assert leaf.status.value == "SUCCESS"
    built.restart()
    assert leaf.status.value == "IDLE"


def test_the_command_prints_the_json_report(
    ticks: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["--json", "--reps", "1", "--min-time", "0", "--wakeup-runs", "3",
            "--recording-s", "0.2"]  # fmt: skip
    assert ticks.main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report) == {
        "trees",
        "wakeup_median_us",
        "wakeup_p99_us",
        "recording_tick_ratio",
        "recording",
    }
    assert report["recording_tick_ratio"] > 0
    for rates in ("at_plan_rate", "flat_out"):
        figures = report["recording"][rates]
        assert figures["ticks_per_s_recording"] > 0 and figures["record_bytes_per_s"] > 0
    assert set(report["trees"]) == set(TREE_IDS)
    for row in report["trees"].values():
        assert set(row) == {"ours_ns", "py_trees_ns", "ratio"}
        assert row["ours_ns"] > 0 and row["py_trees_ns"] > 0
    assert report["wakeup_p99_us"] >= report["wakeup_median_us"] > 0
