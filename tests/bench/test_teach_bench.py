"""bench/teach.py reports the user's actions of the suite's two scripted builds by hand
(Figure 3, the tending set-up) as ``figure3_actions`` and ``tending_setup_actions``, read
from those builds' own tests (they record their count with ``record_property``).

The builds themselves run in the suite (tests/instructor_app/test_end_to_end.py and
test_tending_setup.py, which check the counts); here the bench's reading of them runs on a
stand-in test that records two counts, so the suite does not build both plans twice (66 s).
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]

_STAND_IN = """
def test_figure3(record_property):
    record_property("figure3_actions", 7)


def test_tending(record_property):
    record_property("tending_setup_actions", 11)
    assert False, "a build that fails after counting still reports its count"
"""


def test_the_scripted_builds_action_counts_are_printed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    bench = importlib.import_module("bench.teach")
    builds = tmp_path / "test_builds.py"
    builds.write_text(_STAND_IN, encoding="utf-8")
    monkeypatch.setattr(
        bench,
        "BUILDS",
        {
            f"{builds}::test_figure3": "figure3_actions",
            f"{builds}::test_tending": "tending_setup_actions",
        },
    )
    bench.main(["--json", "--actions-only"])
    figures = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert figures == {"figure3_actions": 7, "tending_setup_actions": 11}


def test_the_bench_names_the_tests_that_count_the_builds(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    bench = importlib.import_module("bench.teach")
    for test_id, figure in bench.BUILDS.items():
        path, _, name = test_id.partition("::")
        source = (REPO_ROOT / path).read_text(encoding="utf-8")
        assert f"def {name}(" in source, test_id
        assert f'"{figure}"' in source, (test_id, figure)  # the test records that figure
