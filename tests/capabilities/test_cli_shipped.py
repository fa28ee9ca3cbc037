"""The command line on the shipped plans: the simulated cell by default, ``example:NAME``,
``costar examples``, and no library banner in the output.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys

import pytest

from capabilities.cli import main
from engine.files import load_plan
from resources import example_name, example_names, example_path, example_plans

pytestmark = pytest.mark.sim  # validate and run start the simulated cell by default

ALL_EXAMPLES = example_names(with_node_examples=True)


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(list(argv), out, err)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name", ALL_EXAMPLES)
def test_every_shipped_example_validates_with_no_options(name: str) -> None:
    code, out, err = run_cli("validate", str(example_path(name)))
    assert code == 0, out + err
    assert out.strip().endswith(": valid")


def test_the_examples_include_the_cell_plans_and_one_per_node_kind() -> None:
    assert {"cup_to_bin", "cup_to_bin_vision", "figure3_debug"} <= set(example_names())
    assert "nodes/retry" in ALL_EXAMPLES
    assert all("/" not in name for name in example_names())


def test_costar_examples_lists_each_plan_with_its_title_and_description() -> None:
    code, out, _ = run_cli("examples")
    assert code == 0
    for path in example_plans():
        plan = load_plan(path)
        assert f"{example_name(path)}: {plan.name}\n" in out
        assert plan.description.split()[0] in out
    assert "nodes/retry" in out and "costar run example:NAME" in out


def test_an_example_validates_and_runs_by_name() -> None:
    code, out, _ = run_cli("validate", "example:cup_to_bin")
    assert code == 0 and out.strip().endswith(": valid")
    code, out, _ = run_cli("run", "example:nodes/sequence", "--rate", "200")
    assert code == 0 and "SUCCESS" in out


def test_an_unknown_example_names_the_shipped_ones() -> None:
    code, _, err = run_cli("validate", "example:teleport")
    assert code == 2
    assert "no shipped example 'teleport'" in err and "cup_to_bin" in err


def test_none_cell_still_chooses_no_robot() -> None:
    code, out, _ = run_cli("validate", "--cell", "none", "example:cup_to_bin")
    assert code == 2
    assert "the none cell has no arm" in out and "leave out --cell none" in out


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", "--help"],
        ["validate", "example:cup_to_bin"],
        ["run", "example:nodes/sequence", "--rate", "200"],
    ],
)
def test_no_pybullet_banner_in_the_output(argv: list[str]) -> None:
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_XDIST_WORKER"}
    done = subprocess.run(
        [sys.executable, "-m", "capabilities.cli", *argv],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "pybullet" not in done.stdout + done.stderr
    assert done.stderr == ""
