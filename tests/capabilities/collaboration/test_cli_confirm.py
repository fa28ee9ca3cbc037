"""``costar run --confirm yes|no|ask`` answers the plan's operator prompts."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from capabilities.cli import main
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import ParamType


def confirm_plan(folder: Path, questions: int = 1) -> str:
    children = [
        NodeSpec(NodeKind.OPERATION, name=f"ask {i}", op="collaboration.confirm",
                 params={"prompt": Binding.fixed(f"Question {i}?", ParamType.TEXT)})
        for i in range(questions)
    ]  # fmt: skip
    path = folder / "confirm.costar.json"
    save_plan(PlanSpec(NodeSpec(NodeKind.SEQUENCE, "steps", children=children), "confirm"), path)
    return str(path)


def run(*argv: str, stdin: str = "") -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    code = main(["run", "--cell", "none", *argv, "--timeout", "60"], out, err, io.StringIO(stdin))
    return code, out.getvalue() + err.getvalue()


def test_confirm_yes_answers_every_prompt_and_the_run_succeeds(tmp_path: Path) -> None:
    code, text = run(confirm_plan(tmp_path, 2), "--confirm", "yes")
    assert code == 0, text
    assert "Question 1? -> yes (--confirm yes)" in text


def test_confirm_no_declines_and_the_run_fails(tmp_path: Path) -> None:
    code, text = run(confirm_plan(tmp_path), "--confirm", "no", "-v")
    assert code == 1
    assert "declined" in text


@pytest.mark.parametrize(
    ("answers", "code"), [("y\nyes\n", 0), ("y\nn\n", 1), ("Y\n", 1), ("n\n", 1)]
)
def test_confirm_ask_reads_one_line_per_prompt_and_end_of_input_says_no(
    tmp_path: Path, answers: str, code: int
) -> None:
    got, text = run(confirm_plan(tmp_path, 2), "--confirm", "ask", stdin=answers)
    assert got == code, text
    assert "Question 0? [y/n]" in text
    if answers == "Y\n":
        assert "Question 1? -> no (end of input)" in text


def test_ask_is_the_default(tmp_path: Path) -> None:
    code, text = run(confirm_plan(tmp_path), stdin="")
    assert code == 1 and "(end of input)" in text
