"""A UR cell opened from a cell file, run by `costar run` and the executor, against the emulator.

The emulator runs in its own process (a real controller is another machine); the client is the
unmodified ur_rtde. Faults are injected while a plan runs: the run is held within one tick with
the reason in words, and goes on from the node that was running once the operator cleared it.
"""

from __future__ import annotations

import io
import json
import threading
from pathlib import Path

import dashboard_client
import jsonschema
import pytest

from capabilities.base import CapabilityRegistry, Cell
from capabilities.cells import CellError, open_cell
from capabilities.cli import main
from capabilities.faults import hold_check
from capabilities.robot.cell_file import DEFAULT_CONFIG_PATH, CellConfig, CellConfigError
from capabilities.ur.connection import SILENCE_S
from engine.build import build_tree
from engine.events import Event, RunHeld, StatusChanged
from engine.executor import Executor
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import RUNNING, SUCCESS
from engine.trace import read_trace
from engine.types import JointConfig, ParamType
from tests.capabilities.ur.emulators import FAST, HOME, wait_for

ROOT = Path(__file__).resolve().parents[3]
SCHEMA = json.loads((ROOT / "resources" / "schemas" / "cell.schema.json").read_text("utf-8"))


def _joints(offset: float) -> tuple[float, ...]:
    return (HOME[0] + offset, *HOME[1:])


def _plan(tmp_path: Path, offsets: tuple[float, ...], speed: float = 1.0) -> tuple[PlanSpec, str]:
    moves = [
        NodeSpec(
            NodeKind.OPERATION,
            f"move {i}",
            op="motion.move_joints",
            params={
                "target": Binding.fixed(JointConfig(_joints(o)), ParamType.JOINTS),
                "speed": Binding.fixed(speed, ParamType.NUMBER),
            },
        )
        for i, o in enumerate(offsets)
    ]
    plan = PlanSpec(NodeSpec(NodeKind.SEQUENCE, "moves", children=moves), "ur moves")
    path = tmp_path / "moves.costar.json"
    save_plan(plan, path)
    return plan, str(path)


# ---------------------------------------------------------------------- the cell file


def test_a_ur_cell_file_reads_round_trips_and_matches_the_schema(tmp_path: Path) -> None:
    data = json.loads(DEFAULT_CONFIG_PATH.read_text("utf-8"))
    jsonschema.validate(data, SCHEMA)
    data["robot"] = {
        "kind": "ur", "host": "127.0.0.9", "model": "UR5 CB3",
        "payload": {"mass": 1.5, "center_of_gravity": [0, 0, 0.04]},
        "tool": {"kind": "suction", "vacuum": "tool 1", "sensor": "standard 3"},
        "inputs": {"pedal": "configurable 2"},
    }  # fmt: skip
    jsonschema.validate(data, SCHEMA)
    path = tmp_path / "my.cell.json"
    path.write_text(json.dumps(data), "utf-8")
    config = CellConfig.load(path)
    robot = config.robot
    assert (robot.kind, robot.host, robot.model) == ("ur", "127.0.0.9", "UR5 CB3")
    assert robot.payload.mass == 1.5 and robot.tool.vacuum == ("tool", 1)
    assert robot.tool.sensor == ("standard", 3) and robot.inputs == {"pedal": ("configurable", 2)}
    again = CellConfig.from_json(config.to_json())
    assert again == config
    jsonschema.validate(config.to_json(), SCHEMA)


@pytest.mark.parametrize(
    ("robot", "where", "what"),
    [
        ({"kind": "ur"}, "$.robot.host", "required"),
        ({"kind": "kuka", "host": "x"}, "$.robot.kind", "one of"),
        (
            {"kind": "ur", "host": "h", "tool": {"vacuum": "tool 2"}},
            "$.robot.tool.vacuum",
            "tool 0-1",
        ),
        ({"kind": "ur", "host": "h", "payload": {"mass": 9}}, "$.robot.payload.mass", ""),
        ({"kind": "sim", "host": "h"}, "$.robot.host", "one of the fields"),
    ],
)
def test_a_bad_robot_block_names_file_and_path(
    tmp_path: Path, robot: dict[str, object], where: str, what: str
) -> None:
    path = tmp_path / "bad.cell.json"
    path.write_text(json.dumps({"format_version": 2, "robot": robot}), "utf-8")
    with pytest.raises(CellConfigError) as info:
        CellConfig.load(path)
    assert str(path) in str(info.value) and where in str(info.value) and what in str(info.value)
    with pytest.raises(CellError, match=r"bad\.cell\.json"):
        open_cell(str(path))


def test_a_version_1_file_still_reads_and_may_not_have_a_robot(tmp_path: Path) -> None:
    path = tmp_path / "old.cell.json"
    path.write_text(json.dumps({"format_version": 1}), "utf-8")
    assert CellConfig.load(path).robot.kind == "sim"
    path.write_text(json.dumps({"format_version": 1, "robot": {"kind": "sim"}}), "utf-8")
    with pytest.raises(CellConfigError, match=r"\$\.robot"):
        CellConfig.load(path)


def test_ur_emulator_command_refuses_a_host_beyond_loopback(capsys) -> None:
    assert main(["ur-emulator", "--host", "192.168.1.5"]) == 2
    assert "not a loopback address" in capsys.readouterr().err


# ---------------------------------------------------------------------- against the emulator


@pytest.mark.sim
def test_costar_run_with_a_cell_file_written_by_the_emulator(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", speed=FAST, write_cell=cell_file)  # moves that end
    assert CellConfig.load(cell_file).robot.host == emulator.host
    spec, _ = _plan(tmp_path, (0.25, -0.1))
    assert spec.tree is not None
    grip = [NodeSpec(NodeKind.OPERATION, op=op) for op in ("gripper.close", "gripper.open")]
    spec.tree.children = [spec.tree.children[0], *grip, spec.tree.children[1]]
    plan = str(tmp_path / "moves_and_gripper.costar.json")
    save_plan(spec, plan)
    out, err = io.StringIO(), io.StringIO()
    trace = tmp_path / "run.trace.jsonl"
    code = main(["run", plan, "--cell", str(cell_file), "--trace", str(trace)], out, err)
    assert code == 0, out.getvalue() + err.getvalue()
    assert "SUCCESS" in out.getvalue()
    assert emulator.state()["q"] == pytest.approx(list(_joints(-0.1)), abs=0.01)
    done = {e["node"] for e in read_trace(trace).events if e.get("new") == "SUCCESS"}
    assert {node.id for node in grip} <= done  # the Robotiq closed and opened
    assert emulator.state()["gripper_closed"] is False


def _ids(plan: PlanSpec) -> list[str]:
    assert plan.tree is not None
    return [child.id for child in plan.tree.children]


def _run(cell: Cell, plan: PlanSpec, events: list[Event]) -> Executor:
    registry = CapabilityRegistry(cell=cell)
    tree = build_tree(plan, registry, clock=cell.clock)
    executor = Executor(
        tree,
        20.0,
        [events.append],
        plan_name=plan.name,
        hold=hold_check(cell),
    )
    executor.start()
    return executor


@pytest.mark.sim
def test_a_protective_stop_holds_the_run_within_a_tick_and_it_resumes_after_the_clear(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    plan, _ = _plan(tmp_path, (0.2, -1.2), speed=0.5)
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        executor = _run(cell, plan, events)
        second = _ids(plan)[1]
        assert wait_for(lambda: executor.tree.nodes[second].status is RUNNING, 20)
        assert wait_for(lambda: emulator.state()["moving"])
        emulator.protective_stop()
        assert wait_for(lambda: cell.connection.state.safety_mode == 3)  # seen by the backend
        seen_at = executor.tree.ctx.tick_count
        assert wait_for(lambda: any(isinstance(e, RunHeld) for e in events))
        held = next(e for e in events if isinstance(e, RunHeld))
        assert held.reason == "protective stop" and held.tick <= seen_at + 1
        assert executor.tree.nodes[second].status is not RUNNING  # halted, not failed
        # The operator unlocks it on the pendant (the dashboard); the cell uploads the script.
        pendant = dashboard_client.DashboardClient(emulator.host)
        pendant.connect()
        pendant.closeSafetyPopup()
        pendant.unlockProtectiveStop()
        result = executor.wait(60)
        assert result is not None and result.status is SUCCESS, result
    reasons = [e.reason for e in events if isinstance(e, RunHeld)]
    # Between the unlock and the script's upload the reason may read "the control script is
    # not running" for a tick or two: the hold says what is missing at each moment.
    assert reasons[0] == "protective stop" and reasons[-1] == "", reasons
    first = _ids(plan)[0]
    assert [e.new for e in events if isinstance(e, StatusChanged) and e.node_id == first] == [
        RUNNING,
        SUCCESS,
    ]  # fmt: skip  (the finished move is not run again)
    assert emulator.state()["q"] == pytest.approx(list(_joints(-1.2)), abs=0.01)


@pytest.mark.sim
def test_a_killed_controller_mid_move_holds_the_run_with_connection_lost(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    # Slow: the move must still be going when the kill lands, also on a loaded machine (at
    # speed 0.5 it once ended first and the run finished with nothing to hold).
    plan, _ = _plan(tmp_path, (1.2,), speed=0.1)
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        executor = _run(cell, plan, events)
        assert wait_for(lambda: emulator.state()["moving"], 20)
        emulator.kill()
        assert wait_for(lambda: executor.held.startswith("connection lost"), 30), executor.held
        node = _ids(plan)[0]
        assert executor.tree.nodes[node].status is not RUNNING
        executor.stop()
        result = executor.wait(20)
        assert result is not None and result.reason == "stopped"


@pytest.mark.sim
def test_cup_to_bin_runs_on_the_emulated_ur_cell_through_ur_rtde(
    tmp_path: Path, start_emulator
) -> None:
    """The real-robot path end to end: ur_rtde moves, the Robotiq URCap grips, the cameras
    are the emulator's frame streams; the cup ends in the bin (ground truth scores it).
    """
    from tests.capabilities.sim.test_cup_to_bin import cup_in_bin

    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", speed=FAST, scene="cup_to_bin", seed=3, write_cell=cell_file)
    out, err = io.StringIO(), io.StringIO()
    plan = str(ROOT / "resources" / "examples" / "cup_to_bin.costar.json")
    code = main(["run", plan, "--cell", str(cell_file), "--timeout", "120"], out, err)
    assert code == 0, out.getvalue() + err.getvalue()
    assert cup_in_bin(emulator.truth_pose("cup"), emulator.truth_pose("waste_bin"))


@pytest.mark.sim
def test_the_pedal_and_the_pendant_teach_button_drive_a_plan(
    tmp_path: Path, start_emulator
) -> None:
    """Pedal (a digital input) -> "continue"; the teach button, held to guide the arm by hand
    and released -> "teach", after which the plan records the waypoint where the arm is.
    """
    emulator_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=emulator_file)
    data = json.loads(emulator_file.read_text("utf-8"))
    data["robot"]["inputs"] = {"pedal": "standard 2"}
    cell_file = tmp_path / "pedal.cell.json"
    cell_file.write_text(json.dumps(data), "utf-8")

    def op(op_id: str, **params: Binding) -> NodeSpec:
        return NodeSpec(NodeKind.OPERATION, op=op_id, params=params)

    text = ParamType.TEXT
    plan = PlanSpec(NodeSpec(NodeKind.SEQUENCE, children=[
        op("collaboration.wait_for_button"),
        op("collaboration.wait_for_button", button=Binding.fixed("teach", text)),
        op("freedrive.record_waypoint", name=Binding.fixed("taught", text),
           frame=Binding.fixed("joints", text), waypoint=Binding.reference("TAUGHT")),
    ]), "teach by hand")  # fmt: skip
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        executor = _run(cell, plan, events)
        first = _ids(plan)[0]
        assert wait_for(lambda: executor.tree.nodes[first].status is RUNNING)
        emulator.set_input("standard", 2, True)  # the foot pedal
        assert wait_for(lambda: executor.tree.nodes[first].status is SUCCESS)
        emulator.teach_button(True)
        assert wait_for(lambda: emulator.state()["freedrive"] is True)  # guided by hand
        joints = emulator.state()["q"]
        assert wait_for(lambda: cell.connection.state.teach_button)
        emulator.teach_button(False)
        result = executor.wait(30)
        assert result is not None and result.status is SUCCESS, (
            [(n.name, n.status, n.message) for n in executor.tree.iterate()],
            cell.operator.presses("teach"),
            executor.held,
        )
        taught = executor.tree.blackboard.snapshot()["TAUGHT"]
    assert taught.name == "taught"
    assert list(taught.joints.positions) == pytest.approx(joints, abs=1e-3)
    assert emulator.state()["freedrive"] is False


@pytest.mark.sim
def test_a_dropped_connection_holds_the_run_and_it_goes_on_once_reconnected(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    plan, _ = _plan(tmp_path, (0.2, -0.6), speed=0.5)
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        executor = _run(cell, plan, events)
        second = _ids(plan)[1]
        assert wait_for(lambda: executor.tree.nodes[second].status is RUNNING, 20)
        # The move is under way (its send is over: a link that drops inside a send leaves
        # ur_rtde waiting up to its 300 s timeout for the answer, see the closing note).
        assert wait_for(lambda: cell.connection.state.moving, 20)
        emulator.disconnect()  # every socket drops for 1 s; the controller is still there
        assert wait_for(lambda: executor.held.startswith("connection lost"), 20), executor.held
        result = executor.wait(60)  # the cell reconnects by itself, the run goes on
        assert result is not None and result.status is SUCCESS, (result, executor.held)
        # No kicks while the link was away; the script's watchdog is kicked again after it.
        assert wait_for(lambda: cell.connection.watchdog_armed, 20)
    reasons = [e.reason for e in events if isinstance(e, RunHeld)]
    assert reasons[-1] == "" and any(r.startswith("connection lost") for r in reasons)
    assert emulator.state()["q"] == pytest.approx(list(_joints(-0.6)), abs=0.01)


@pytest.mark.sim
def test_a_controller_not_heard_from_holds_the_run_until_it_answers_again(
    tmp_path: Path, start_emulator
) -> None:
    """The I/O thread stuck in a ur_rtde call (as in a move's send when the controller dies
    under it): its last state says all is well, but it is old: the run holds, and goes on
    once the thread reads the controller again.
    """
    cell_file = tmp_path / "emulated.cell.json"
    start_emulator("5.12", speed=FAST, write_cell=cell_file)  # held before the move starts
    plan, _ = _plan(tmp_path, (0.3,), speed=0.5)
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        release = threading.Event()
        stuck = cell.connection.submit(lambda: release.wait(SILENCE_S + 20))
        executor = _run(cell, plan, events)
        assert wait_for(lambda: executor.held.startswith("connection lost"), SILENCE_S + 10), (
            executor.held
        )
        assert "no word from the controller" in cell.status().problem
        assert not cell.status().connected
        release.set()
        stuck.result(5)
        result = executor.wait(60)
        assert result is not None and result.status is SUCCESS, (result, executor.held)
    assert [e.reason for e in events if isinstance(e, RunHeld)][-1] == ""


@pytest.mark.sim
def test_a_dead_control_script_holds_the_run_until_the_operator_clears_it(
    tmp_path: Path, start_emulator
) -> None:
    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    plan, _ = _plan(tmp_path, (0.9,), speed=0.5)
    events: list[Event] = []
    with open_cell(str(cell_file)) as cell:
        executor = _run(cell, plan, events)
        assert wait_for(lambda: emulator.state()["moving"], 20)
        emulator.kill_script()  # as if stopped on the pendant: no stop to clear
        assert wait_for(lambda: executor.held.startswith("the control script is not running"))
        ticks = executor.tree.ctx.tick_count
        # Nobody cleared it: the script stays gone and the run stays held (no tick runs).
        assert not wait_for(lambda: emulator.state()["program_running"], 2.0)
        assert executor.held and executor.tree.ctx.tick_count == ticks
        cell.clear()  # the operator's clear: the script is uploaded again
        result = executor.wait(60)
        assert result is not None and result.status is SUCCESS, (result, executor.held)
    assert emulator.state()["q"] == pytest.approx(list(_joints(0.9)), abs=0.01)


@pytest.mark.sim
def test_costar_run_says_a_protective_stop_and_finishes_after_the_unlock(
    tmp_path: Path, start_emulator
) -> None:
    import threading

    cell_file = tmp_path / "emulated.cell.json"
    emulator = start_emulator("5.12", write_cell=cell_file)
    _, plan = _plan(tmp_path, (1.0,), speed=0.5)
    out, err = io.StringIO(), io.StringIO()

    def operator() -> None:  # another person at the cell: a stop, then the unlock
        assert wait_for(lambda: emulator.state()["moving"], 30)
        emulator.protective_stop()
        assert wait_for(lambda: "held: protective stop" in out.getvalue(), 20)
        pendant = dashboard_client.DashboardClient(emulator.host)
        pendant.connect()
        pendant.unlockProtectiveStop()

    thread = threading.Thread(target=operator, daemon=True)
    thread.start()
    code = main(["run", plan, "--cell", str(cell_file), "--timeout", "60"], out, err)
    thread.join(30)
    text = out.getvalue()
    assert code == 0, text + err.getvalue()
    assert "held: protective stop" in text and "the run goes on" in text
    assert emulator.state()["q"] == pytest.approx(list(_joints(1.0)), abs=0.01)
