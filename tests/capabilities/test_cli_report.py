"""``costar run`` reads like the GUI: values in mm and degrees, and a success that came through
a fallback names the nodes that failed on the way.
"""

from __future__ import annotations

import io
from pathlib import Path

from capabilities.cli import main
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec, RunPolicy
from engine.types import ParamType, Pose


def run(plan: PlanSpec, tmp_path: Path, *options: str) -> tuple[int, str]:
    path = tmp_path / "plan.costar.json"
    save_plan(plan, path)
    out, err = io.StringIO(), io.StringIO()
    code = main(["run", "--cell", "none", "--rate", "200", str(path), *options], out, err)
    return code, out.getvalue() + err.getvalue()


def test_a_success_through_a_fallback_names_what_failed_and_what_caught_it(
    tmp_path: Path,
) -> None:
    why = Binding.fixed("collision with the table", ParamType.TEXT)
    move = NodeSpec(
        NodeKind.OPERATION, "move to CUP_POSE", op="debug.fail", params={"message": why}
    )
    wait = NodeSpec(NodeKind.OPERATION, "wait instead", op="debug.succeed")
    tree = NodeSpec(NodeKind.SELECTOR, "transfer or wait", children=[move, wait])
    code, out = run(PlanSpec(tree, "fallback"), tmp_path)
    assert code == 0
    lines = out.splitlines()
    assert lines[-3].startswith("fallback: SUCCESS after")
    assert lines[-2:] == [
        "  on the way:",
        "  - move to CUP_POSE failed: collision with the table; caught by Selector "
        "'transfer or wait'",
    ]


def _pick_behind_a_retry_and_a_fallback(ask: NodeSpec) -> NodeSpec:
    why = Binding.fixed("nothing between the fingers", ParamType.TEXT)
    error = Binding.fixed("grasp_failed", ParamType.TEXT)
    pick = NodeSpec(
        NodeKind.OPERATION, "grasp CUP", op="debug.fail", params={"message": why, "error": error}
    )
    count = Binding.fixed(4, ParamType.NUMBER)
    retry = NodeSpec(NodeKind.RETRY, "pick 4 times", params={"count": count}, children=[pick])
    return NodeSpec(NodeKind.SELECTOR, "pick or ask", children=[retry, ask])


def test_a_failed_run_names_the_pick_its_message_and_the_count_in_its_last_lines(
    tmp_path: Path,
) -> None:
    """The pick fails 4 times behind a retry and a fallback, whose option fails too."""
    why = Binding.fixed("no one answered", ParamType.TEXT)
    ask = NodeSpec(NodeKind.OPERATION, "ask for help", op="debug.fail", params={"message": why})
    code, out = run(PlanSpec(_pick_behind_a_retry_and_a_fallback(ask), "pick"), tmp_path)
    assert code == 1
    lines = out.splitlines()
    assert lines[-3].startswith("pick: FAILURE after ")
    assert lines[-3].endswith(
        " ticks (grasp CUP failed 4 times (grasp_failed): nothing between the fingers; "
        "passed up by Retry 'pick 4 times', Selector 'pick or ask')"
    )
    assert lines[-2:] == [
        "  on the way:",
        "  - ask for help failed: no one answered; passed up by Selector 'pick or ask'",
    ]


def test_until_success_stops_after_identical_failures_and_says_so(tmp_path: Path) -> None:
    why = Binding.fixed("no one answered", ParamType.TEXT)
    ask = NodeSpec(NodeKind.OPERATION, "ask for help", op="debug.fail", params={"message": why})
    tree = _pick_behind_a_retry_and_a_fallback(ask)
    plan = PlanSpec(tree, "pick", run_policy=RunPolicy.UNTIL_SUCCESS, give_up_after=2)
    code, out = run(plan, tmp_path)
    assert code == 1
    (result,) = [line for line in out.splitlines() if line.startswith("pick: FAILURE after ")]
    assert result.endswith(
        " ticks (stopped after 2 identical failures in a row: grasp CUP failed 8 times "
        "(grasp_failed): nothing between the fingers; passed up by Retry 'pick 4 times', "
        "Selector 'pick or ask')"
    )


def test_a_plain_success_has_no_failures_to_tell(tmp_path: Path) -> None:
    tree = NodeSpec(NodeKind.OPERATION, "done", op="debug.succeed")
    code, out = run(PlanSpec(tree, "plain"), tmp_path)
    assert code == 0 and "on the way" not in out


def test_verbose_shows_poses_in_mm_and_degrees(tmp_path: Path) -> None:
    pose = Pose((0.421, 0.2802, -1.09e-05), (0.0, 0.0, 0.2563, 0.9666))
    value = Binding.fixed(pose, ParamType.POSE)
    query = NodeSpec(NodeKind.OPERATION, "cup pose", op="debug.query",
                     params={"value": value, "result": Binding.reference("CUP_POSE")})  # fmt: skip
    code, out = run(PlanSpec(query, "pose"), tmp_path, "--verbose")
    assert code == 0, out
    assert "  CUP_POSE = (421.0, 280.2, 0.0) mm, rpy (0.0, 0.0, 29.7)°" in out
    assert "e-05" not in out
