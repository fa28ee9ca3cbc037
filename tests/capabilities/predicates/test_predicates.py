"""The Predicator's conditions on constructed geometry: detections put straight into a world
model of a fake cell (world, arm, the real object library), no simulator.
"""

from __future__ import annotations

import json
import math
import re
import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from capabilities.base import CapabilityRegistry
from capabilities.object_library import ObjectLibrary, default_library_path
from capabilities.predicates import capability
from capabilities.world_model import Detection, WorldModel
from engine.operations import Job, OperationCall, OperationFailed
from engine.status import SUCCESS
from engine.types import ObjectModel, Pose

DOWN = (1.0, 0.0, 0.0, 0.0)  # a TCP whose z axis points at the table


def yaw(x: float, y: float, z: float, angle: float = 0.0) -> Pose:
    return Pose((x, y, z), (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)))


class FakeArm:
    def __init__(self) -> None:
        self.tcp = Pose((0.3, 0.0, 0.5), DOWN)

    def tcp_pose(self) -> Pose:
        return self.tcp

    def joint_positions(self) -> tuple[float, ...]:
        return (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)


class FakeCell:
    name = "fake"

    def __init__(self, library: ObjectLibrary | None = None) -> None:
        self.world = WorldModel()
        self.arm = FakeArm()
        self.library = library or ObjectLibrary()
        self.now = 0.0

    def interfaces(self) -> Mapping[str, Any]:
        return {"world": self.world, "arm": self.arm, "objects": self.library}

    def clock(self) -> float:
        return self.now

    def put(self, name: str, pose: Pose, stamp: float | None = None) -> None:
        stamp = self.now if stamp is None else stamp
        self.world.replace(f"test:{name}", [Detection(name, pose, 1.0, stamp, "test")])


ROBOT_BASE = Pose((0.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))  # turned 180 deg, as in the sim cell


@pytest.fixture
def cell() -> FakeCell:
    return FakeCell()


@pytest.fixture
def registry(cell: FakeCell) -> CapabilityRegistry:
    return CapabilityRegistry([capability()], cell=cell,
                              settings={"predicates": {"robot_base": ROBOT_BASE}})  # fmt: skip


def check(registry: CapabilityRegistry, op_id: str, **args: Any) -> tuple[bool, str]:
    """Evaluate a predicate once: (holds, message). It must answer in the first poll."""
    manifest = registry.manifest(op_id)
    call = OperationCall("n", op_id, {}, lambda *_: None, lambda *_: None, lambda: None,
                         registry.cell.clock)  # fmt: skip
    objects = {k: ObjectModel(v) if isinstance(v, str) and k.startswith("object") else v
               for k, v in args.items()}  # fmt: skip
    call.args = {p.name: p.default for p in manifest.inputs} | objects
    job = registry.create(op_id).start(call)
    assert isinstance(job, Job) and job.finished, "a predicate must answer at once"
    return job.poll() is SUCCESS, job.message


# ------------------------------------------------------------------ relations


def test_directions_in_the_world_frame(cell: FakeCell, registry: CapabilityRegistry) -> None:
    cell.put("cup", yaw(0.5, 0.2, 0.0))
    cell.put("plate_4_holes", yaw(0.45, 0.0, 0.0))
    truth = {"left_of": True, "right_of": False, "in_front_of": True, "behind": False,
             "up_from": True, "down_from": False}  # fmt: skip
    for relation, expected in truth.items():
        holds, message = check(registry, f"predicates.{relation}", object_a="cup",
                               object_b="plate_4_holes")  # fmt: skip
        assert holds is expected, (relation, message)
    holds, message = check(registry, "predicates.left_of", object_a="cup",
                           object_b="plate_4_holes", margin=0.25)  # fmt: skip
    assert not holds and "200 mm left of plate_4_holes" in message
    holds, _ = check(registry, "predicates.left_of", object_a="plate_4_holes", object_b="cup")
    assert not holds


def test_the_frame_of_reference_switches_the_answer(
    cell: FakeCell, registry: CapabilityRegistry
) -> None:
    cell.put("cup", yaw(0.5, 0.2, 0.0))
    cell.put("plate_4_holes", yaw(0.5, 0.0, 0.0, math.pi))  # the plate turned half round
    args = {"object_a": "cup", "object_b": "plate_4_holes"}
    assert check(registry, "predicates.left_of", **args, frame="world")[0]
    holds, message = check(registry, "predicates.left_of", **args, frame="object_b")
    assert not holds and "object b frame" in message
    assert check(registry, "predicates.right_of", **args, frame="object_b")[0]
    # The robot base frame is turned 180 deg too: its left is the world's right.
    assert not check(registry, "predicates.left_of", **args, frame="robot")[0]
    assert check(registry, "predicates.right_of", **args, frame="robot")[0]
    # A plate turned a quarter: the cup is now in front of it, not left of it.
    cell.put("plate_4_holes", yaw(0.5, 0.0, 0.0, math.pi / 2))
    assert check(registry, "predicates.in_front_of", **args, frame="object_b")[0]
    assert not check(registry, "predicates.left_of", **args, frame="object_b")[0]


def test_up_and_down_use_the_objects_centres(cell: FakeCell, registry: CapabilityRegistry) -> None:
    cell.put("plate_8_holes", yaw(0.5, 0.0, 0.0))
    cell.put("cup", yaw(0.5, 0.0, 0.006))  # standing on the plate
    assert check(registry, "predicates.up_from", object_a="cup", object_b="plate_8_holes")[0]
    assert check(registry, "predicates.down_from", object_a="plate_8_holes", object_b="cup")[0]
    holds, message = check(registry, "predicates.up_from", object_a="cup",
                           object_b="plate_8_holes", margin=0.06)  # fmt: skip
    assert not holds and "53 mm up from" in message  # (0.006 + 0.05) - 0.003


def test_an_unseen_object_or_a_bad_frame_fails_with_a_reason(
    cell: FakeCell, registry: CapabilityRegistry
) -> None:
    cell.put("cup", yaw(0.5, 0.2, 0.0))
    with pytest.raises(OperationFailed, match="plate_4_holes has not been seen"):
        check(registry, "predicates.left_of", object_a="cup", object_b="plate_4_holes")
    cell.put("plate_4_holes", yaw(0.5, 0.0, 0.0))
    with pytest.raises(OperationFailed, match="unknown frame 'ceiling'"):
        check(registry, "predicates.left_of", object_a="cup", object_b="plate_4_holes",
              frame="ceiling")  # fmt: skip


# ------------------------------------------------------------------ motion


def _feed(cell: FakeCell, registry: CapabilityRegistry, name: str, times: np.ndarray,
          positions: np.ndarray) -> None:  # fmt: skip
    """Detections at ``times``, each evaluated once (as a reactive plan would each tick)."""
    for t, xyz in zip(times, positions, strict=True):
        cell.now = float(t)
        cell.put(name, Pose.of(xyz), stamp=float(t))
        check(registry, "predicates.is_moving", object=name)


def test_moving_and_stationary_over_a_window(cell: FakeCell, registry: CapabilityRegistry) -> None:
    rng = np.random.default_rng(0)
    times = np.arange(0.0, 1.0, 1 / 15)  # 15 detections a second
    sliding = np.column_stack((0.4 + 0.05 * times, np.zeros_like(times), np.zeros_like(times)))
    _feed(cell, registry, "cup", times, sliding + rng.normal(0, 0.0005, sliding.shape))
    holds, message = check(registry, "predicates.is_moving", object="cup")
    assert holds and "moves at 50 mm/s" in message, message
    assert not check(registry, "predicates.is_stationary", object="cup")[0]
    assert not check(registry, "predicates.is_moving", object="cup", speed=0.08)[0]

    still = np.tile((0.6, 0.1, 0.0), (len(times), 1)) + rng.normal(0, 0.0005, (len(times), 3))
    _feed(cell, registry, "plate_3_holes", times + 1.0, still)
    assert check(registry, "predicates.is_stationary", object="plate_3_holes")[0]
    assert not check(registry, "predicates.is_moving", object="plate_3_holes")[0]


def test_too_few_detections_are_neither_moving_nor_stationary(
    cell: FakeCell, registry: CapabilityRegistry
) -> None:
    cell.now = 5.0
    cell.put("cup", Pose((0.5, 0.0, 0.0)), stamp=5.0)
    for op_id in ("predicates.is_moving", "predicates.is_stationary"):
        holds, message = check(registry, op_id, object="cup")
        assert not holds and "too few to tell" in message
    cell.now = 7.0  # the last detection is now older than the window
    cell.put("cup", Pose((0.5, 0.0, 0.0)), stamp=5.0)
    assert not check(registry, "predicates.is_stationary", object="cup", window=1.0)[0]


# ------------------------------------------------------------------ contact


@pytest.mark.parametrize(
    ("gap", "touching", "near"),
    [(-0.002, True, True), (0.0, True, True), (0.01, False, True), (0.1, False, False)],
)
def test_touching_near_and_apart(
    cell: FakeCell, registry: CapabilityRegistry, gap: float, touching: bool, near: bool
) -> None:
    cell.put("plate_4_holes", yaw(0.5, 0.0, 0.0))
    cell.put("cup", yaw(0.5, 0.05 + 0.04 + gap, 0.0))  # the cup's side gap from the plate's edge
    args = {"object_a": "cup", "object_b": "plate_4_holes"}
    holds, message = check(registry, "predicates.touching", **args)
    assert holds is touching, message
    assert f"{gap * 1000:.1f} mm apart" in message or gap < 0, message
    assert check(registry, "predicates.near_collision", **args)[0] is near


def test_a_cup_inside_the_bin_does_not_touch_it_until_it_rests_on_its_floor(
    cell: FakeCell, registry: CapabilityRegistry
) -> None:
    args = {"object_a": "cup", "object_b": "waste_bin"}
    cell.put("waste_bin", yaw(0.6, 0.0, 0.0, 0.3))
    cell.put("cup", yaw(0.6, 0.0, 0.05))  # hanging inside the bin's walls
    holds, message = check(registry, "predicates.touching", **args)
    assert not holds and "42.0 mm apart" in message, message  # 50 mm above an 8 mm floor
    cell.put("cup", yaw(0.6, 0.0, 0.008))
    assert check(registry, "predicates.touching", **args)[0]


@pytest.mark.parametrize(("height", "touching", "near"),
                         [(0.11, True, True), (0.13, False, True), (0.5, False, False)])  # fmt: skip
def test_the_tool_touching_an_object(
    cell: FakeCell, registry: CapabilityRegistry, height: float, touching: bool, near: bool
) -> None:
    cell.put("cup", yaw(0.3, 0.0, 0.0))
    cell.arm.tcp = Pose((0.3, 0.0, height), DOWN)  # fingertips reach 15 mm below the TCP
    assert check(registry, "predicates.tool_touching", object="cup")[0] is touching
    holds, message = check(registry, "predicates.tool_near_collision", object="cup")
    assert holds is near, message


def test_convex_hull_models_collide_by_their_mesh(tmp_path: Path) -> None:
    folder = tmp_path / "objects"
    shutil.copytree(default_library_path() / "cup", folder / "hull_cup")
    model = json.loads((folder / "hull_cup" / "model.json").read_text())
    model.update(name="hull_cup", collision={"type": "convex_hull"})
    (folder / "hull_cup" / "model.json").write_text(json.dumps(model))
    cell = FakeCell(ObjectLibrary(folder))
    registry = CapabilityRegistry([capability()], cell=cell)
    cell.put("hull_cup", yaw(0.5, 0.0, 0.0))
    cell.arm.tcp = Pose((0.5, 0.0, 0.12), DOWN)
    holds, message = check(registry, "predicates.tool_near_collision", object="hull_cup")
    # 20 mm above the rim, fingertips 15 mm lower: 5 mm (pybullet's hull margin takes ~1 mm).
    gap = float(re.findall(r"([-\d.]+) mm apart", message)[0])
    assert holds and 3.0 <= gap <= 6.0, message
    cell.arm.tcp = Pose((0.5, 0.0, 0.2), DOWN)
    assert not check(registry, "predicates.tool_near_collision", object="hull_cup")[0]
