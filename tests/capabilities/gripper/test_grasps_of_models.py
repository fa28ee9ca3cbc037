"""Grasps taught once in the object models: they load, and their equivalents honour the
object's symmetry (a fake arm whose reach the test chooses; no simulator).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, cast

import pytest

from capabilities.gripper.grasp import FIRST, GraspPlan, plan_grasp
from capabilities.gripper.operations import capability
from capabilities.motion.backend import ArmBackend
from capabilities.motion.geometry import rotation_between
from capabilities.motion.symmetry import SymmetryTable
from capabilities.object_library import ObjectLibrary, ObjectLibraryError
from engine.operations import OperationFailed
from engine.types import Pose

DOWN = (1.0, 0.0, 0.0, 0.0)


def _yawed(yaw: float, at: tuple[float, float, float] = (0.5, 0.1, 0.0)) -> Pose:
    return Pose(at, (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


class ReachArm:
    """Reaches a pose when ``reach(pose)`` says so; the tool stands at ``tcp``."""

    def __init__(self, tcp: Pose, reach: object = None) -> None:
        self.tcp = tcp
        self.reach = reach or (lambda pose: True)
        self.asked: list[Pose] = []

    def tcp_pose(self) -> Pose:
        return self.tcp

    def inverse_kinematics(
        self, pose: Pose, near: Sequence[float] | None = None
    ) -> tuple[float, ...] | None:
        self.asked.append(pose)
        return (0.0,) * 6 if self.reach(pose) else None  # type: ignore[operator]


def _plan(arm: ReachArm, *args: Any) -> GraspPlan:
    return plan_grasp(cast(ArmBackend, arm), *args)  # the fake has what plan_grasp reads


def test_models_carry_their_grasps() -> None:
    library = ObjectLibrary()
    cup = library.get("cup")
    assert [(g.name, g.tool) for g in cup.grasps] == [("top", "gripper"), ("rim", "gripper")]
    assert cup.grasp().name == "top" and cup.grasp("rim").pose.position == (0.0, 0.0, 0.085)
    for plate in ("plate_3_holes", "plate_4_holes", "plate_8_holes"):
        grasp = library.get(plate).grasp()
        thickness = library.get(plate).dimensions[2]
        assert (grasp.name, grasp.tool) == ("suction", "suction")
        assert grasp.pose.position[2] == pytest.approx(thickness - 0.0005)
        assert grasp.approach.position[2] > grasp.pose.position[2] + 0.05
    with pytest.raises(ObjectLibraryError, match=r"no grasp 'side' \(it has top, rim\)"):
        cup.grasp("side")
    with pytest.raises(ObjectLibraryError, match="waste_bin has no grasps"):
        library.get("waste_bin").grasp()


def test_the_grasp_port_offers_the_library_grasps_first_by_default() -> None:
    manifests = {d.manifest.id: d.manifest for d in capability().operations}
    port = manifests["gripper.grasp"].port("grasp")
    assert port is not None and port.default == FIRST
    assert port.choices == (FIRST, "top", "rim", "suction", "weld")


def test_continuous_symmetry_turns_the_grasp_toward_the_wrist() -> None:
    table = SymmetryTable()
    grasp = table.grasp("cup")
    wrist = Pose((0.4, 0.0, 0.3), (1.0, 0.0, 0.0, 0.0))
    for cup_yaw in (0.0, 1.0, 2.5, -2.0):  # the cup's yaw is meaningless: it is round
        plan = _plan(ReachArm(wrist), grasp, _yawed(cup_yaw), table, "cup")
        assert rotation_between(plan.hold, wrist) < 1e-6
        assert plan.hold.position == pytest.approx((0.5, 0.1, 0.06))
        assert plan.approach.position == pytest.approx((0.5, 0.1, 0.22))


def test_discrete_symmetry_uses_the_next_equivalent_when_the_first_is_out_of_reach() -> None:
    table = SymmetryTable()
    grasp = table.grasp("plate_8_holes")  # order 2 about z
    wrist = Pose((0.4, 0.0, 0.3), DOWN)
    plate = _yawed(0.3)
    first = _plan(ReachArm(wrist), grasp, plate, table, "plate_8_holes")
    assert first.equivalent == 0
    refused = first.hold.orientation
    arm = ReachArm(wrist, lambda pose: rotation_between(pose, Pose((0, 0, 0), refused)) > 0.1)
    second = _plan(arm, grasp, plate, table, "plate_8_holes")
    assert second.equivalent == 1
    assert rotation_between(second.hold, first.hold) == pytest.approx(math.pi)
    assert second.hold.position == pytest.approx(first.hold.position)


def test_no_reachable_equivalent_fails_in_mm() -> None:
    table = SymmetryTable()
    arm = ReachArm(Pose((0.4, 0.0, 0.3), DOWN), lambda pose: False)
    with pytest.raises(OperationFailed, match=r"unreachable: grasp 'suction' of the plate_4_holes"
                       r".*\(500.0, 100.0, 0.0\) mm.*none of 4 symmetric equivalents"):  # fmt: skip
        _plan(arm, table.grasp("plate_4_holes"), _yawed(0.0), table, "plate_4_holes")
