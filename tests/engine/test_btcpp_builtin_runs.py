"""Trees of BehaviorTree.CPP's built-in nodes run here to the statuses, tick by tick, and the
entries BehaviorTree.CPP 4.10 itself gave (tests/engine/data/btcpp/builtins_run_by_btcpp.txt,
written by tools/btcpp/run_xml.cpp from the files in tests/engine/data/btcpp/builtins).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from capabilities.base import CapabilityRegistry
from engine.btcpp import import_xml
from engine.build import build_tree
from engine.status import RUNNING

DATA = Path(__file__).parent / "data" / "btcpp"
CASES = DATA / "builtins"


def _expected() -> dict[str, tuple[list[str], dict[str, str]]]:
    """Case -> (statuses tick by tick, entries as BehaviorTree.CPP printed them)."""
    runs: dict[str, tuple[list[str], dict[str, str]]] = {}
    statuses: list[str] = []
    entries: dict[str, str] = {}
    for line in (DATA / "builtins_run_by_btcpp.txt").read_text(encoding="utf-8").splitlines():
        if line.startswith("== "):
            statuses, entries = [], {}
            runs[line[3:]] = (statuses, entries)
        elif line.startswith("bb "):
            key, shown = line[3:].split(" = ", 1)
            if shown != "?":  # an entry BehaviorTree.CPP declared and never wrote
                entries[key] = shown
        else:
            statuses.append(line)
    return runs


EXPECTED = _expected()


def _shown(value: Any) -> str:
    if isinstance(value, str):
        return f"'{value}'"
    if isinstance(value, bool):
        return str(int(value))
    return str(value) if isinstance(value, int) else f"{value:g}"


def test_every_case_has_btcpp_results() -> None:
    assert sorted(EXPECTED) == sorted(p.stem for p in CASES.glob("*.xml"))


@pytest.mark.parametrize("case", sorted(EXPECTED))
def test_the_run_matches_btcpp_tick_by_tick(registry: CapabilityRegistry, case: str) -> None:
    statuses, entries = EXPECTED[case]
    spec = import_xml((CASES / f"{case}.xml").read_text(encoding="utf-8"), f"{case}.xml")
    tree = build_tree(spec, registry)
    ours = [tree.tick().value]
    while ours[-1] == RUNNING.value and len(ours) < 50:
        ours.append(tree.tick().value)
    assert ours == statuses
    board = tree.blackboard
    # BehaviorTree.CPP printed its root blackboard: a subtree instance's own entries
    # (``Inner#id/name``) are not in it.
    top = [key for key in board if "/" not in key]
    assert {key: _shown(board.get(key)) for key in top} == entries
