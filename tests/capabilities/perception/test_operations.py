"""The perception capability's operations on the simulated cell (rendered frames only;
ground truth is read here to score them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.jobs import WorkerPool
from capabilities.object_library import ObjectLibrary
from capabilities.perception import capability
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import run
from capabilities.world_model import WorldModel
from engine.build import build_tree
from engine.executor import run_to_end
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.types import ObjectModel, ParamType, Pose
from tests.capabilities.perception.shots import OBSERVE_JOINTS

pytestmark = pytest.mark.sim


def _op(op: str, **params: Binding) -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, name=op, op=op, params=params)


def _obj(name: str) -> Binding:
    return Binding.fixed(ObjectModel(name), ParamType.OBJECT)


def _run(cell: Any, *nodes: NodeSpec) -> tuple[Status, dict[str, Any], str]:
    registry = CapabilityRegistry([capability()], cell=cell)
    built = build_tree(PlanSpec(NodeSpec(NodeKind.SEQUENCE, children=list(nodes))), registry,
                       clock=cell.clock)  # fmt: skip
    result = run_to_end(built, 100.0, timeout=60.0)
    messages = " | ".join(n.message for n in built.iterate() if n.message)
    return result.status, built.blackboard.snapshot(), messages


def _looking(scene: str, seed: int) -> SimCellSession:
    session = SimCellSession(scene, seed=seed)
    run(session.sim.robot.move_joints(OBSERVE_JOINTS))
    return session


def test_detect_then_query_poses_and_counts() -> None:
    with _looking("perception", 0) as cell:
        status, board, messages = _run(
            cell,
            _op("perception.detect_objects", count=Binding.reference("N")),
            _op("perception.object_found", object=_obj("cup")),
            _op("perception.object_pose", object=_obj("cup"), pose=Binding.reference("CUP")),
            _op("perception.objects_of_class", object=_obj("plate_4_holes"),
                count=Binding.reference("PLATES"), poses=Binding.reference("WHERE")),
        )  # fmt: skip
        assert status is Status.SUCCESS, messages
        assert math.dist(board["CUP"].position, cell.truth_pose("cup").position) < 0.01
        assert board["N"] == len(cell.scene.names())
        assert board["PLATES"] == 1.0 and len(board["WHERE"]) == 1
        detections = cell.world_model.detections("cup")
        assert [d.source for d in detections] == ["perception:shoulder"]
        assert detections[0].instance == "cup#1"


def test_identities_persist_between_looks_and_follow_a_moved_object() -> None:
    with _looking("cup_to_bin", 1) as cell:
        assert _run(cell, _op("perception.detect_objects"))[0] is Status.SUCCESS
        before = cell.truth_pose("cup")
        moved = Pose((before.position[0] + 0.02, before.position[1], before.position[2]),
                     before.orientation)  # fmt: skip
        cell.sim.call(lambda client: cell.scene.remove(client, "cup"))
        cell.sim.call(lambda client: cell.scene.spawn(client, "cup", "cup", moved))
        assert _run(cell, _op("perception.detect_objects"))[0] is Status.SUCCESS
        cup = cell.world_model.best("cup")
        assert cup is not None and cup.instance == "cup#1"
        assert math.dist(cup.pose.position, moved.position) < 0.01


def test_plate_type_names_the_plate_nearest_a_pose() -> None:
    with _looking("kitting", 2) as cell:
        truth = cell.truth_pose("plate_8_holes")
        status, board, messages = _run(
            cell,
            _op("perception.detect_objects"),
            _op("perception.plate_type", near=Binding.fixed(truth, ParamType.POSE),
                within=Binding.fixed(0.03, ParamType.NUMBER),
                model=Binding.reference("TYPE"), pose=Binding.reference("WHERE")),
        )  # fmt: skip
        assert status is Status.SUCCESS, messages
        assert board["TYPE"] == ObjectModel("plate_8_holes")
        assert math.dist(board["WHERE"].position, truth.position) < 0.01


def test_operations_fail_cleanly_when_nothing_is_seen() -> None:
    with _looking("empty", 0) as cell:
        status, board, _ = _run(
            cell,
            _op("perception.detect_objects", count=Binding.reference("N")),
            _op("perception.objects_of_class", object=_obj("cup"), count=Binding.reference("C")),
        )  # fmt: skip
        assert status is Status.SUCCESS and board["N"] == 0.0 and board["C"] == 0.0
        assert _run(cell, _op("perception.object_found", object=_obj("cup")))[0] is Status.FAILURE
        status, _, messages = _run(
            cell, _op("perception.object_pose", object=_obj("cup"), pose=Binding.reference("P"))
        )
        assert status is Status.FAILURE and "has not been seen" in messages
        status, _, messages = _run(cell, _op("perception.plate_type", model=Binding.reference("T")))
        assert status is Status.FAILURE and "no plate seen" in messages


class _NoCameraCell:
    name = "camera-less"

    def __init__(self) -> None:
        self._interfaces = {
            "world": WorldModel(),
            "workers": WorkerPool(1),
            "objects": ObjectLibrary(),
        }

    def interfaces(self) -> Mapping[str, Any]:
        return self._interfaces

    def clock(self) -> float:
        return 0.0


def test_unavailable_without_cameras() -> None:
    cell = _NoCameraCell()
    registry = CapabilityRegistry([capability()], cell=cell)
    availability = registry.availability("perception.detect_objects")
    assert not availability.available and "rgbd:shoulder" in availability.reason
    cell.interfaces()["workers"].close()
