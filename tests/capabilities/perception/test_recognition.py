"""Recognition on rendered frames of the simulated cell, scored against ground truth."""

from __future__ import annotations

import math
import statistics

import numpy as np
import pytest

from capabilities.perception.errors import PerceptionError
from capabilities.perception.evaluation import score_recognitions, visible_fraction
from capabilities.perception.geometry import pose_to_matrix, yaw_of
from capabilities.perception.recognizer import Recognition, Recognizer
from capabilities.perception.scene_cloud import segment_scene
from tests.capabilities.perception.shots import Shot


def _scores(
    shots: list[Shot], recognitions: list[list[Recognition]], recognizer: Recognizer
) -> list:
    scores = []
    for shot, found in zip(shots, recognitions, strict=True):
        visible = {
            name: (model, pose)
            for name, (model, pose) in shot.truth.items()
            if visible_fraction(shot.frame, recognizer.models.get(model), pose) >= 0.5
        }
        scores += score_recognitions(found, visible, recognizer.models.library)
    return scores


def test_recall_and_pose_errors_meet_the_targets(
    shots: list[Shot], recognitions: list[list[Recognition]], recognizer: Recognizer
) -> None:
    scores = _scores(shots, recognitions, recognizer)
    found = [s for s in scores if s.found]
    assert len(scores) >= 30
    assert len(found) / len(scores) >= 0.95, [s for s in scores if not s.found]
    assert statistics.median(s.position_error for s in found) < 0.01
    assert statistics.median(s.rotation_error for s in found) < math.radians(5)


def test_plates_are_classified_by_their_holes(
    shots: list[Shot], recognitions: list[list[Recognition]], recognizer: Recognizer
) -> None:
    scores = [s for s in _scores(shots, recognitions, recognizer) if s.model.startswith("plate_")]
    assert len(scores) >= 15
    right = sum(s.nearest_class == s.model for s in scores)
    assert right / len(scores) >= 0.95, [(s.model, s.nearest_class) for s in scores]


def test_symmetric_objects_get_the_canonical_yaw(recognitions: list[list[Recognition]]) -> None:
    yaws: dict[str, list[float]] = {}
    for found in recognitions[:4]:
        for r in found:
            yaws.setdefault(r.object_class, []).append(yaw_of(pose_to_matrix(r.pose)[:3, :3]))
    assert all(abs(y) < 1e-6 for y in yaws["cup"])  # continuous symmetry: yaw 0
    assert all(-math.pi / 2 - 1e-6 <= y <= math.pi / 2 + 1e-6 for y in yaws["waste_bin"])
    assert all(abs(y) <= math.pi / 4 + 1e-6 for y in yaws["plate_4_holes"])


def test_table_plane_and_clusters(shots: list[Shot], recognizer: Recognizer) -> None:
    scene = segment_scene(shots[0].frame, recognizer.config)
    up = scene.T_world_table[:3, 2]
    assert up[2] > 0.999 and abs(scene.T_world_table[2, 3]) < 0.002  # the table top is z = 0
    assert len(scene.clusters) >= len(shots[0].truth)


def test_no_table_in_view_is_a_perception_error(shots: list[Shot], recognizer: Recognizer) -> None:
    frame = shots[0].frame
    blind = type(frame)(
        frame.rgb, np.full_like(frame.depth, np.nan), frame.K, frame.T_world_camera, 0.0
    )
    with pytest.raises(PerceptionError):
        recognizer.recognize(blind)
