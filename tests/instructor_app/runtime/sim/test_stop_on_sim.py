"""Stop during a motion on the simulated cell: the run ends and the arm stands still short of
its target (the leaf is halted and its capability stops the arm).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from engine.files import dump_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.types import JointConfig, ParamType
from instructor_app.document.editing import PlanDocument
from instructor_app.runtime.controller import RunController
from instructor_app.runtime.session import CellSession


@pytest.fixture
def sim_session(qapp: Any) -> Iterator[CellSession]:
    session = CellSession("sim", speed=1.0)  # real time: the motion takes seconds
    assert session.open(), "the simulated cell did not open"
    yield session
    session.close()


def test_stop_halts_the_arm(qtbot: Any, sim_session: CellSession) -> None:
    robot = sim_session.cell.interfaces()["arm"]
    home = robot.home_joints()
    target = (home[0] + 1.5, *home[1:])  # a slow turn of the base: about 5 s at 0.3
    move = NodeSpec(
        NodeKind.OPERATION, name="turn", op="motion.move_joints",
        params={
            "target": Binding.fixed(JointConfig(target), ParamType.JOINTS),
            "speed": Binding.fixed(0.3, ParamType.NUMBER),
        },
    )  # fmt: skip
    document = PlanDocument()
    plan = PlanSpec(tree=NodeSpec(NodeKind.SEQUENCE, name="top", children=[move]), name="turn")
    document.load_text(dump_plan(plan), None)
    controller = RunController(document, sim_session)
    assert controller.run()
    qtbot.waitUntil(robot.is_moving, timeout=5000)
    with qtbot.waitSignal(controller.run_finished, timeout=5000) as blocker:
        controller.stop()
    assert blocker.args[0].event.reason == "stopped"
    qtbot.waitUntil(lambda: not robot.is_moving(), timeout=3000)
    stood = robot.joint_positions()[0]
    assert abs(stood - target[0]) > 0.5  # it stopped well short of the target
