"""bench/teach.py reports the user's actions of the suite's two scripted builds by hand
(Figure 3, the tending set-up) as ``figure3_actions`` and ``tending_setup_actions``, from
those builds' own tests (figures not asserted beyond being counts).
"""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.sim  # the builds run on the simulated cells, in a child pytest


def test_the_scripted_builds_action_counts_are_printed(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.syspath_prepend(str(REPO_ROOT))
    bench = importlib.import_module("bench.teach")
    bench.main(["--json", "--actions-only"])
    figures = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert set(figures) == {"figure3_actions", "tending_setup_actions"}
    assert all(isinstance(n, int) and n > 0 for n in figures.values()), figures
