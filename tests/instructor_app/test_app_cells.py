"""costar-instructor --cell: the cell opens after the window shows, and --screenshot waits for
it (a run for the picture needs the arm), also when it fails (a UR host that does not answer).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import JointConfig, ParamType
from instructor_app.app import EXIT_OK, main
from tests.capabilities.ur.emulators import HOME


@pytest.mark.sim
def test_a_screenshot_run_waits_for_the_simulated_cell(
    qapp: Any, tmp_path: Path, capsys: Any
) -> None:
    move = NodeSpec(NodeKind.OPERATION, "turn", op="motion.move_joints", params={
        "target": Binding.fixed(JointConfig((HOME[0] + 0.3, *HOME[1:])), ParamType.JOINTS),
    })  # fmt: skip
    plan = tmp_path / "turn.costar.json"
    plan.write_text(dump_plan(PlanSpec(move, "turn")), encoding="utf-8")
    png = tmp_path / "turn.png"
    args = [str(plan), "--cell", "sim", "--run", "--screenshot", str(png), "--size", "800x600"]
    assert main(args) == EXIT_OK  # refused ("still opening") had it not waited
    assert "run ended: SUCCESS" in capsys.readouterr().out and png.is_file()


def test_a_cell_file_whose_robot_does_not_answer_is_named_and_the_picture_taken(
    qapp: Any, tmp_path: Path, capsys: Any
) -> None:
    cell_file = tmp_path / "dead.cell.json"
    robot = {"kind": "ur", "host": "127.254.0.1", "model": "UR5e"}
    cell_file.write_text(json.dumps({"format_version": 2, "robot": robot}), "utf-8")
    png = tmp_path / "dead.png"
    args = ["--cell", str(cell_file), "--screenshot", str(png), "--size", "800x600"]
    assert main(args) == EXIT_OK
    err = capsys.readouterr().err
    assert "cannot connect to the UR controller at 127.254.0.1" in err and png.is_file()
