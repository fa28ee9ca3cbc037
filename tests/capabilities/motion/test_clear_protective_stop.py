"""motion.clear_protective_stop: its failure types from what the arm's clear says (the runs on
the simulated cell and the UR emulator are in tests/capabilities/sim and tests/capabilities/ur).
"""

from __future__ import annotations

import time

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.robot.commands import CommandHandle
from engine.build import build_tree
from engine.error_types import ErrorType
from engine.spec import NodeKind, NodeSpec, PlanSpec
from engine.status import FAILURE, SUCCESS


class _Arm:
    """An arm whose clear finishes as told (the rest of ArmBackend is never called)."""

    def __init__(self, ok: bool, message: str) -> None:
        self.ok, self.message = ok, message

    def clear_protective_stop(self) -> CommandHandle:
        handle = CommandHandle("clear_protective_stop")
        handle.resolve(self.ok, self.message)
        return handle


class _Cell:
    name = "fake"

    def __init__(self, arm: _Arm) -> None:
        self.arm = arm

    def interfaces(self) -> dict[str, object]:
        return {"arm": self.arm}

    def clock(self) -> float:
        return time.monotonic()


@pytest.mark.parametrize(
    ("ok", "message", "status", "error"),
    [
        (True, "unlocked", SUCCESS, None),
        (False, "clear_protective_stop: timed out", FAILURE, ErrorType.TIMEOUT),
        (False, "clear_protective_stop: emergency stop (for the operator to clear)", FAILURE,
         ErrorType.EMERGENCY_STOP),
        (False, "clear_protective_stop: the arm is powered off (for the operator to clear)",
         FAILURE, ErrorType.FAILED),
    ],
)  # fmt: skip
def test_the_failure_type_follows_what_the_arm_said(
    ok: bool, message: str, status: object, error: ErrorType | None
) -> None:
    node = NodeSpec(NodeKind.OPERATION, "clear", "clear", op="motion.clear_protective_stop")
    registry = CapabilityRegistry(cell=_Cell(_Arm(ok, message)))
    tree = build_tree(PlanSpec(node), registry, clock=time.monotonic)
    assert tree.tick_until_done(1000) is status
    leaf = tree.nodes["clear"]
    assert leaf.error is error
    if not ok:
        assert leaf.message == f"clear protective stop: {message}"
