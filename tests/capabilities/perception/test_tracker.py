"""The surface tracker keeps identities between frames and gives new objects new ids."""

from __future__ import annotations

import math

from capabilities.object_library import Symmetry
from capabilities.perception.geometry import matrix_to_pose, pose_to_matrix, upright_matrix, yaw_of
from capabilities.perception.recognizer import Recognition
from capabilities.perception.tracker import SurfaceTracker


def _seen(cls: str, x: float, y: float, yaw: float = 0.0) -> Recognition:
    return Recognition(cls, matrix_to_pose(upright_matrix(x, y, yaw)), 0.9)


def _ids(pairs: list[tuple[str, Recognition]]) -> list[str]:
    return [instance for instance, _ in pairs]


def test_identities_persist_when_objects_move_a_little() -> None:
    tracker = SurfaceTracker(gate=0.05)
    first = tracker.update([_seen("cup", 0.4, 0.0), _seen("cup", 0.6, 0.1)], 0.0)
    assert _ids(first) == ["cup#1", "cup#2"]
    # listed in the other order and each moved 2 cm: the ids follow the objects
    second = tracker.update([_seen("cup", 0.62, 0.1), _seen("cup", 0.4, 0.02)], 1.0)
    assert _ids(second) == ["cup#2", "cup#1"]


def test_a_new_object_gets_a_new_id_and_ids_are_not_reused() -> None:
    tracker = SurfaceTracker(gate=0.05, max_missed=0)
    tracker.update([_seen("cup", 0.4, 0.0), _seen("waste_bin", 0.6, -0.2)], 0.0)
    pairs = tracker.update([_seen("cup", 0.4, 0.0), _seen("cup", 0.5, 0.3)], 1.0)
    assert _ids(pairs) == ["cup#1", "cup#2"]
    # the bin was missed once (max_missed=0): forgotten; a bin seen again is a new bin
    assert _ids(tracker.update([_seen("waste_bin", 0.6, -0.2)], 2.0)) == ["waste_bin#2"]


def test_an_object_that_jumps_beyond_the_gate_is_a_new_one() -> None:
    tracker = SurfaceTracker(gate=0.05)
    tracker.update([_seen("cup", 0.4, 0.0)], 0.0)
    assert _ids(tracker.update([_seen("cup", 0.5, 0.0)], 1.0)) == ["cup#2"]


def test_classes_are_tracked_apart() -> None:
    tracker = SurfaceTracker(gate=0.05)
    tracker.update([_seen("plate_3_holes", 0.4, 0.0)], 0.0)
    assert _ids(tracker.update([_seen("plate_4_holes", 0.4, 0.0)], 1.0)) == ["plate_4_holes#1"]


def test_a_symmetric_object_keeps_a_steady_yaw() -> None:
    tracker = SurfaceTracker(symmetries={"waste_bin": Symmetry("discrete", order=2)})
    tracker.update([_seen("waste_bin", 0.6, 0.0, yaw=1.5)], 0.0)
    # the next frame reads the same bin a half turn round (equivalent): reported near 1.5
    ((_, steady),) = tracker.update([_seen("waste_bin", 0.6, 0.0, yaw=1.6 - math.pi)], 1.0)
    assert math.isclose(yaw_of(pose_to_matrix(steady.pose)[:3, :3]), 1.6, abs_tol=1e-9)
