"""Every example plan validates and runs to the result its description states."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from engine.build import build_tree
from engine.executor import run_to_end
from engine.files import dump_plan, load_plan
from engine.validation import has_errors, validate_plan
from resources import plan_argument

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
DEBUG_PLANS = sorted(
    [EXAMPLES / "figure3_debug.costar.json", *(EXAMPLES / "nodes").glob("*.costar.json")]
)


def test_there_is_one_example_per_node_kind() -> None:
    from engine.spec import NodeKind

    kinds_used = set()
    for path in DEBUG_PLANS:
        kinds_used |= {node.kind for _, node in load_plan(path).walk()}
    assert kinds_used == set(NodeKind)


def test_examples_are_reproduced_by_their_generator() -> None:
    from tools.generators import make_examples

    assert dump_plan(make_examples.figure3()) == (EXAMPLES / "figure3_debug.costar.json").read_text(
        encoding="utf-8"
    )
    for name, plan in make_examples.node_examples().items():
        assert dump_plan(plan) == (EXAMPLES / "nodes" / f"{name}.costar.json").read_text(
            encoding="utf-8"
        )


@pytest.mark.parametrize("path", DEBUG_PLANS, ids=lambda p: p.stem)
def test_example_runs_to_the_stated_result(path: Path) -> None:
    registry = CapabilityRegistry()
    plan = load_plan(path, aliases=registry.aliases())
    problems = validate_plan(plan, registry)
    assert not has_errors(problems), problems
    stated = re.search(r"Runs to (SUCCESS|FAILURE)\.", plan.description)
    assert stated, f"{path.name}: the description must say what it runs to"
    result = run_to_end(build_tree(plan, registry), rate_hz=100.0, timeout=30.0)
    assert result.reason == "finished"
    assert result.status.value == stated.group(1)


def test_cell_examples_are_reproduced_by_their_generator() -> None:
    from capabilities.waypoints import WaypointLibrary, waypoints_path_for
    from tools.generators import make_cell_examples

    plan_path = EXAMPLES / "cup_to_bin.costar.json"
    assert dump_plan(make_cell_examples.cup_to_bin()) == plan_path.read_text(encoding="utf-8")
    stored = WaypointLibrary.load(waypoints_path_for(plan_path))
    assert list(stored) == make_cell_examples.waypoints()
    vision = EXAMPLES / "cup_to_bin_vision.costar.json"
    assert dump_plan(make_cell_examples.cup_to_bin_vision()) == vision.read_text(encoding="utf-8")
    tending = EXAMPLES / "tending_paper.costar.json"
    assert dump_plan(make_cell_examples.tending_paper()) == tending.read_text(encoding="utf-8")
    assert (
        list(WaypointLibrary.load(waypoints_path_for(tending)))
        == make_cell_examples.tending_waypoints()
    )


@pytest.mark.parametrize("name", ["cup_to_bin", "tending_paper"])
def test_cell_examples_validate_on_the_sim_cell_interfaces(name: str) -> None:
    """Validated against the registry of a cell with the simulated cell's interfaces."""
    registry = CapabilityRegistry(cell=_InterfacesOnly())
    plan = load_plan(EXAMPLES / f"{name}.costar.json", aliases=registry.aliases())
    problems = validate_plan(plan, registry)
    assert not has_errors(problems), problems


class _InterfacesOnly:
    """A cell that has the simulated cell's interfaces but no simulator (validation only)."""

    name = "sim-like"

    def interfaces(self) -> dict[str, object]:
        names = ("arm", "gripper", "suction", "freedrive", "rgbd:shoulder", "rgbd:wrist", "world",
                 "workers", "scene_layout", "objects", "operator")  # fmt: skip
        return {name: object() for name in names}

    def clock(self) -> float:
        return 0.0


def test_the_command_an_example_suggests_names_it_as_costar_finds_it() -> None:
    """``costar run cup_to_bin.costar.json`` only works inside resources/examples: a shipped
    plan is run as ``example:NAME`` (its path under the examples, without .costar.json).
    """
    for path in sorted(EXAMPLES.rglob("*.costar.json")):
        description = json.loads(path.read_text(encoding="utf-8")).get("description", "")
        for plan in re.findall(r"costar run (\S+)", description):
            assert plan.startswith("example:"), f"{path.name} suggests costar run {plan}"
            assert Path(plan_argument(plan.rstrip("."))).is_file()  # as the CLI reads it
