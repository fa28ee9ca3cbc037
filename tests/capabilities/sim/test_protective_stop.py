"""A collision in the simulated cell is a protective stop, reported as the UR cell reports one,
and a plan handles it: thrown into a Catch that runs ClearStopAndBackOff, or held until the
operator clears it (the run then goes on from the node that was running).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.bullet import pybullet
from capabilities.faults import PROTECTIVE_STOP, fault_error, hold_check
from capabilities.robot.cell_file import CellConfig
from capabilities.robot.cell_robot import RobotSettings
from capabilities.robot.commands import CommandHandle
from capabilities.sim.bender_spec import FaultModel
from capabilities.sim.errors import SimError
from capabilities.sim.scene import default_scene_path
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import add_box, down_at, run
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.events import Event, LogMessage, RunFinished, RunHeld, StatusChanged
from engine.executor import Executor
from engine.library import SHIPPED_LIBRARY, load_subtree
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ParamType, Pose

pytestmark = pytest.mark.sim

CLEAR_STOP = SHIPPED_LIBRARY / "recovery" / "ClearStopAndBackOff.subtree.json"
ABOVE = down_at(0.5, 0.0, 0.25)
INTO_THE_TABLE = down_at(0.5, 0.0, -0.05)  # the fingers reach the table top first


def quick_config(unlock_delay: float = 1.0) -> CellConfig:
    return dataclasses.replace(CellConfig.load(), robot=RobotSettings(unlock_delay=unlock_delay))


def move(name: str, target: Pose, linear: bool = True) -> NodeSpec:
    params = {"target": Binding.fixed(target, ParamType.POSE)}
    if linear:
        params["mode"] = Binding.fixed("linear", ParamType.TEXT)
    return NodeSpec(NodeKind.OPERATION, name, name, op="motion.move_to", params=params)


def caught(body: NodeSpec, plan_name: str) -> PlanSpec:
    """``body`` in a Catch of protective_stop whose handler is ClearStopAndBackOff."""
    subtree = load_subtree(CLEAR_STOP)
    handler = NodeSpec(NodeKind.SUBTREE, "recover", "recover", subtree=subtree.ref)
    catch = NodeSpec(NodeKind.CATCH, "catch", "catch", children=[body, handler], params={
        "errors": Binding.fixed("protective_stop", ParamType.TEXT),
        "error": Binding.fixed("WHY", ParamType.TEXT),
    })  # fmt: skip
    return PlanSpec(catch, plan_name, subtrees=[subtree])


def start(session: SimCellSession, plan: PlanSpec, events: list[Event]) -> Executor:
    registry = CapabilityRegistry(cell=session)
    tree = build_tree(plan, registry, clock=session.clock)
    executor = Executor(tree, 50.0, [events.append], plan.name, hold=hold_check(session))
    executor.start()
    return executor


def failures(events: list[Event], node_id: str) -> list[tuple[str, str]]:
    return [
        (e.error, e.message)
        for e in events
        if isinstance(e, StatusChanged) and e.node_id == node_id and e.new is Status.FAILURE
    ]


def at_safe_pose(session: SimCellSession) -> bool:
    safe = session.sim.config.home_joints  # the subtree's default safe pose
    joints = session.sim.robot.joint_positions()
    return max(abs(a - b) for a, b in zip(joints, safe, strict=True)) < 0.01


def finish(handle: CommandHandle) -> CommandHandle:
    """Wait for a command that may fail (the timeout only bounds a failing test)."""
    assert handle.wait(60.0), f"{handle.name} did not finish"
    return handle


def test_driving_into_the_table_is_a_protective_stop_in_the_ur_cells_words() -> None:
    # A delay far longer than the checks below take in simulated time, even on a loaded
    # machine (the cell runs as fast as it can while the test thread looks).
    with SimCellSession("cup_to_bin", config=quick_config(30.0)) as session:
        robot = session.sim.robot
        assert session.hold_reason() == "" and session.status() is None
        run(robot.move_pose_joint_space(ABOVE))
        handle = finish(robot.move_linear(INTO_THE_TABLE, 0.1))
        assert handle.ok is False and PROTECTIVE_STOP in handle.message, handle.message
        assert "on the table" in handle.message  # what touched what, with the force
        assert fault_error(handle.message) is ErrorType.PROTECTIVE_STOP
        assert robot.tcp_pose().position[2] > 0.0  # stopped at once, on the table top
        assert session.hold_reason() == PROTECTIVE_STOP  # the UR cell's words
        status = session.status()
        assert status is not None and status.problem == PROTECTIVE_STOP
        assert status.clear_action == ""  # too early: the status bar offers no unlock yet
        again = finish(robot.move_linear(ABOVE))
        assert again.ok is False and PROTECTIVE_STOP in again.message  # refused until cleared
        with pytest.raises(SimError, match="cannot unlock the protective stop until 30 s"):
            session.clear_protective_stop()  # PolyScope's rule: not before the delay
        session.sim.wait_sim(30.0)
        status = session.status()
        assert status is not None and status.clear_action == "Unlock protective stop"
        session.clear_protective_stop()
        assert session.hold_reason() == "" and session.status() is None
        assert run(robot.move_linear(ABOVE)).ok


def test_a_catch_of_protective_stop_around_the_move_runs_clear_stop_and_back_off() -> None:
    body = NodeSpec(NodeKind.SEQUENCE, "pick", "pick", children=[
        move("above", ABOVE, linear=False), move("down", INTO_THE_TABLE),
    ])  # fmt: skip
    events: list[Event] = []
    with SimCellSession("cup_to_bin", config=quick_config(1.0)) as session:
        executor = start(session, caught(body, "into the table"), events)
        result = executor.wait(120.0)
        assert result is not None and result.status is Status.SUCCESS, "; ".join(
            f"{e.node_id} {e.message}" for e in events if isinstance(e, (StatusChanged, LogMessage))
        )
        (error, message), *_ = failures(events, "down")
        assert error == ErrorType.PROTECTIVE_STOP.value and PROTECTIVE_STOP in message
        assert executor.tree.blackboard.get("WHY").startswith("protective_stop: ")
        assert not [e for e in events if isinstance(e, RunHeld)]  # the plan handled it
        assert session.hold_reason() == "" and at_safe_pose(session)


def test_without_a_catch_the_run_is_held_and_the_operators_clear_resumes_it() -> None:
    plan = PlanSpec(NodeSpec(NodeKind.SEQUENCE, "go", "go", children=[
        move("above", ABOVE, linear=False), move("down", down_at(0.5, 0.0, 0.06)),
    ]), "blocked")  # fmt: skip
    events: list[Event] = []
    with SimCellSession("cup_to_bin", config=quick_config(1.0)) as session:
        fixture = add_box(session.sim, (0.2, 0.2, 0.08), (0.5, 0.0), mass=0.0)  # in the way
        executor = start(session, plan, events)
        assert _wait(lambda: executor.held == PROTECTIVE_STOP)
        assert not failures(events, "down")  # held, not failed: the node keeps its place
        session.sim.call(lambda client: pybullet.removeBody(fixture, physicsClientId=client))
        session.clear()  # the status bar's button: unlocks once the delay allows
        result = executor.wait(120.0)
        assert result is not None and result.status is Status.SUCCESS, result
        assert [e.reason for e in events if isinstance(e, RunHeld)] == [PROTECTIVE_STOP, ""]
        assert abs(session.sim.robot.tcp_pose().position[2] - 0.06) < 0.002  # it got there


def test_the_welding_arm_pushing_the_waiting_robot_is_thrown_into_the_catch(
    tmp_path: Path,
) -> None:
    data = json.loads(default_scene_path("tending").read_text(encoding="utf-8"))
    data["bender"].update(parts=2, interval=8.0, first_at=[1.0, 1.0])
    scene = tmp_path / "tending_two.json"
    scene.write_text(json.dumps(data), encoding="utf-8")
    no_faults = FaultModel(bad_weld=0.0, bad_grasp=0.0)
    wait = NodeSpec(NodeKind.WAIT, "wait at the exit", "wait", params={
        "seconds": Binding.fixed(60.0, ParamType.DURATION),
    })  # fmt: skip
    # Real time: the robot reaches the exit 2.6 s before the arm comes down, and the Wait must
    # be running by then; as fast as possible, starting the run could take longer than that.
    with SimCellSession(scene, seed=5, speed=1.0, faults=no_faults) as session:  # 5 s delay
        bender = session.bender
        assert bender is not None
        first, second = bender.release_times()
        events: list[Event] = []
        plan = caught(wait, "in the way")
        registry = CapabilityRegistry(cell=session)
        tree = build_tree(plan, registry, clock=session.clock)
        executor = Executor(tree, 50.0, [events.append], plan.name, hold=hold_check(session))
        session.sim.wait_sim(first + 0.8 - session.clock())
        part = bender.produced()[0].part
        pose, grasp = session.truth_pose(part), session.scene.model(part).grasp()
        run(session.sim.robot.move_pose_joint_space(pose.compose(grasp.approach)))
        run(session.sim.robot.move_linear(pose.compose(grasp.pose)))  # at the exit
        assert session.clock() < second - bender.spec.swing  # before the arm comes down
        executor.start()
        result = executor.wait(120.0)
        assert result is not None and result.status is Status.SUCCESS, result
        assert session.clock() > second - bender.spec.swing  # the arm came down on it
        assert failures(events, "wait") == [(ErrorType.PROTECTIVE_STOP.value, PROTECTIVE_STOP)]
        thrown = [e.message for e in events if isinstance(e, LogMessage) and e.node_id == "wait"]
        assert thrown == ["the cell threw protective_stop into the plan: protective stop"]
        assert executor.tree.blackboard.get("WHY") == "protective_stop: protective stop"
        assert session.hold_reason() == "" and at_safe_pose(session)
        assert isinstance(events[-1], RunFinished)


def _wait(predicate: Callable[[], bool], timeout: float = 60.0) -> bool:
    """Poll until ``predicate`` holds (the timeout only bounds a failing test)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return False


def test_a_cell_file_sets_the_force_limit_and_the_unlock_delay() -> None:
    config = CellConfig.from_json(
        {"format_version": 2, "robot": {"kind": "sim", "force_limit": 90, "unlock_delay": 0.5}}
    )
    assert (config.robot.force_limit, config.robot.unlock_delay) == (90.0, 0.5)
    assert CellConfig.from_json(config.to_json()) == config
    assert CellConfig().to_json()["robot"] == {"kind": "sim"}
    with pytest.raises(Exception, match="force_limit"):
        CellConfig.from_json({"format_version": 2, "robot": {"kind": "sim", "force_limit": 0}})
    with pytest.raises(Exception, match="unlock_delay"):
        CellConfig.from_json(
            {"format_version": 2, "robot": {"kind": "ur", "host": "127.0.0.2", "unlock_delay": 1}}
        )
    assert math.isclose(RobotSettings().force_limit, 150.0)
