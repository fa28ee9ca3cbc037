"""Version-1 plan files (every shipped example as it was before format 2) still open."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.executor import run_to_end
from engine.files import load_plan
from engine.validation import has_errors, validate_plan

V1 = Path(__file__).resolve().parent / "data" / "v1"
V1_PLANS = sorted(V1.rglob("*.costar.json"))
# The format-2 files of examples that changed since (cup to bin now grasps with the object's
# grasp): what the version-1 file must still mean.
V2_AT_MIGRATION = Path(__file__).resolve().parent / "data" / "v2"


def test_every_v1_example_was_kept() -> None:
    assert len(V1_PLANS) == 22


@pytest.mark.parametrize("path", V1_PLANS, ids=lambda p: p.relative_to(V1).as_posix())
def test_v1_file_loads_and_validates(path: Path) -> None:
    cell_example = path.parent == V1 and path.name.startswith("cup_to_bin")
    registry = CapabilityRegistry(cell=_InterfacesOnly()) if cell_example else CapabilityRegistry()
    plan = load_plan(path, aliases=registry.aliases())
    assert plan.tree is not None
    problems = validate_plan(plan, registry)
    assert not has_errors(problems), problems
    if cell_example:
        return
    stated = re.search(r"Runs to (SUCCESS|FAILURE)\.", plan.description)
    assert stated, f"{path.name}: the description must say what it runs to"
    result = run_to_end(build_tree(plan, registry), rate_hz=100.0, timeout=30.0)
    assert result.reason == "finished"
    assert result.status.value == stated.group(1)


class _InterfacesOnly:
    """A cell that has the simulated cell's interfaces but no simulator (validation only)."""

    name = "sim-like"

    def interfaces(self) -> dict[str, object]:
        names = ("arm", "gripper", "suction", "freedrive", "rgbd:shoulder", "rgbd:wrist", "world",
                 "workers", "scene_layout", "objects")  # fmt: skip
        return {name: object() for name in names}

    def clock(self) -> float:
        return 0.0


@pytest.mark.parametrize("path", V1_PLANS, ids=lambda p: p.relative_to(V1).as_posix())
def test_v1_file_means_what_the_shipped_v2_file_means(path: Path) -> None:
    """The reader turns "config" and timing.wait into the ports and Wait node of format 2."""
    shipped = V2_AT_MIGRATION / path.relative_to(V1)
    if not shipped.exists():
        shipped = (
            Path(__file__).resolve().parents[2] / "resources" / "examples" / path.relative_to(V1)
        )
    assert '"format_version": 1' in path.read_text(encoding="utf-8")
    assert '"format_version": 2' in shipped.read_text(encoding="utf-8")
    assert load_plan(path) == load_plan(shipped)
