"""timing: wait_until polls a condition of the same registry, on the cell's clock."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import pytest

from capabilities.base import Capability, CapabilityEnv, CapabilityRegistry, NullCell
from capabilities.debug import capability as debug
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import down_at
from capabilities.timing import capability as timing
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.operations import Job, OperationKind, OperationManifest
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.tree import BehaviorTree
from engine.validation import validate_plan
from tests.capabilities.motion.plans import op, registry_for, run_plan


class ProbeCell:
    """A cell with a hand-set clock and one flag that a condition reads."""

    name = "probe"

    def __init__(self) -> None:
        self.now = 0.0
        self.flag = False

    def interfaces(self) -> Mapping[str, Any]:
        return {"probe": self}

    def clock(self) -> float:
        return self.now


def _probe() -> Capability:
    cap = Capability("probe", "a flag", requires=("probe",))

    class IsSet:
        MANIFEST = OperationManifest("probe.is_set", OperationKind.CONDITION, "the flag", "probe")

        def __init__(self, env: CapabilityEnv) -> None:
            self.cell: ProbeCell = env.interface("probe")

        def start(self, call: object) -> Job:
            return Job.answer(self.cell.flag)

    cap.add(IsSet)
    return cap


def _tree(cell: Any, node: NodeSpec) -> BehaviorTree:
    registry = CapabilityRegistry([timing(), debug(), _probe()], cell=cell)
    return build_tree(PlanSpec(node, "t"), registry, clock=cell.clock)


def test_wait_until_succeeds_when_the_condition_turns_true() -> None:
    cell = ProbeCell()
    tree = _tree(cell, op("timing.wait_until", condition="probe.is_set", timeout=2.0))
    assert tree.tick() is Status.RUNNING
    cell.now, cell.flag = 1.0, True
    assert tree.tick() is Status.SUCCESS


def test_wait_until_fails_after_the_timeout() -> None:
    cell = ProbeCell()
    node = op("timing.wait_until", "until", condition="probe.is_set", timeout=2.0)
    tree = _tree(cell, node)
    assert tree.tick() is Status.RUNNING
    cell.now = 1.99
    assert tree.tick() is Status.RUNNING
    cell.now = 2.0
    assert tree.tick() is Status.FAILURE
    assert tree.nodes[node.id].message == "timed out after 2 s waiting for probe.is_set"
    assert tree.nodes[node.id].error is ErrorType.TIMEOUT


def test_wait_until_checks_once_per_tick_with_the_condition_defaults() -> None:
    cell = ProbeCell()
    tree = _tree(cell, op("timing.wait_until", condition="debug.succeed_after"))
    assert [tree.tick() for _ in range(3)] == [Status.RUNNING, Status.RUNNING, Status.SUCCESS]


@pytest.mark.parametrize(
    ("condition", "expected"),
    [
        ("no.such_op", "there is no operation 'no.such_op'"),
        ("debug.succeed", "debug.succeed is an action, not a condition"),
        ("debug.check_param", "debug.check_param needs value, expected"),
        ("", "needs the id of a condition operation"),
    ],
)
def test_wait_until_refuses_what_it_cannot_run(condition: str, expected: str) -> None:
    node = op("timing.wait_until", "until", condition=condition)
    tree = _tree(ProbeCell(), node)
    assert tree.tick() is Status.FAILURE
    assert expected in tree.nodes[node.id].message


def test_wait_until_finds_conditions_of_its_own_registry() -> None:
    from capabilities.debug import capability as debug

    registry = CapabilityRegistry([timing(), debug()], cell=NullCell())
    node = op("timing.wait_until", condition="debug.succeed_after")
    tree = build_tree(PlanSpec(node, "t"), registry)
    assert [tree.tick() for _ in range(3)] == [Status.RUNNING, Status.RUNNING, Status.SUCCESS]


# ---------------------------------------------------------------- on the simulated cell


@pytest.fixture
def session() -> Iterator[SimCellSession]:
    with SimCellSession("empty") as cell:
        yield cell


@pytest.mark.sim
def test_wait_until_the_arm_moves_in_parallel_with_a_move(session: SimCellSession) -> None:
    registry = registry_for(session)
    parallel = NodeSpec(
        NodeKind.PARALLEL,
        children=[
            op("motion.move_to", target=down_at(0.4, -0.2, 0.25), speed=0.3),  # long enough to see
            op("timing.wait_until", "until moving", condition="motion.is_moving", timeout=5.0),
        ],
    )
    run = run_plan(session, parallel, registry)
    assert run.status is Status.SUCCESS, run.failure()
    assert run.messages()["until moving"] == "motion.is_moving became true"


@pytest.mark.parametrize(
    ("condition", "expected"),
    [
        ("", "needs the id of a condition operation"),
        ("probe.is_sett", "names no operation: 'probe.is_sett' (did you mean"),
        ("debug.succeed", "debug.succeed is an action, not a condition"),
    ],
)
def test_validation_checks_the_condition_id(condition: str, expected: str) -> None:
    registry = CapabilityRegistry([timing(), debug(), _probe()], cell=ProbeCell())
    plan = PlanSpec(op("timing.wait_until", condition=condition), "t")
    messages = [p.message for p in validate_plan(plan, registry) if p.severity == "error"]
    assert len(messages) == 1 and expected in messages[0], messages


def test_validation_accepts_a_runnable_condition() -> None:
    registry = CapabilityRegistry([timing(), debug(), _probe()], cell=ProbeCell())
    plan = PlanSpec(op("timing.wait_until", condition="probe.is_set"), "t")
    assert validate_plan(plan, registry) == []
