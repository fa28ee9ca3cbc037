"""Helpers of the perception tests: frames of the simulated cell with their ground truth."""

from __future__ import annotations

from dataclasses import dataclass

from capabilities.sim.cameras import RGBDFrame
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import run
from engine.types import Pose

__all__ = ["OBSERVE_JOINTS", "SCENES", "Shot", "take_shots"]

OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)  # the arm out of the shoulder camera's view
SCENES = [("perception", seed) for seed in range(6)] + [("kitting", 0), ("kitting", 1)]


@dataclass
class Shot:
    """One shoulder-camera frame and the GROUND TRUTH (name -> (model, pose)) to score it."""

    scene: str
    seed: int
    frame: RGBDFrame
    truth: dict[str, tuple[str, Pose]]


def take_shots(scenes: list[tuple[str, int]]) -> list[Shot]:
    """One frame of each (scene, seed) with the arm out of view; the cells are closed after."""
    found = []
    for scene, seed in scenes:
        with SimCellSession(scene, seed=seed) as session:
            run(session.sim.robot.move_joints(OBSERVE_JOINTS))
            frame = session.cameras["shoulder"].capture()
            truth = {
                n: (session.scene.model(n).name, session.truth_pose(n))
                for n in session.scene.names()
            }
            found.append(Shot(scene, seed, frame, truth))
    return found
