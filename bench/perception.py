"""Model-based recognition on the simulated cell: recall, pose errors, plate types, time.

Over N scenes (seeds 0..N-1 of ``resources/scenes/perception.json``: a cup, a waste bin and
the three plates, the bin and each plate present with probability 0.8), the arm steps out of
the shoulder camera's view, the camera takes one 640x480 frame and the recogniser runs on it.
Ground truth scores it (and only scores it):

- ``recall``: objects recognised with the right class within 2 cm and 10 deg of the truth,
  over the objects visible (at least half of their camera-facing surface in view);
- ``median_pos_err_m`` / ``median_rot_err_deg``: over the recognised objects (rotation error
  modulo the model's symmetry: any yaw for the cup);
- ``plate_accuracy``: visible plates whose nearest recognition (within 3 cm) has the right
  plate class, over the visible plates;
- ``detect_ms_median``: wall time of one recognition (segmentation + matching) per frame,
  excluding the render; ``false_positives``: recognitions that match no object.

Run from the repository root::

    .venv/bin/python bench/perception.py [--scenes 50] [--json]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from typing import Any

from capabilities.object_library import ObjectLibrary
from capabilities.perception.evaluation import ObjectScore, score_recognitions, visible_fraction
from capabilities.perception.recognizer import Recognition, Recognizer
from capabilities.sim.session import SimCellSession
from capabilities.sim.testing import run

OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)  # the arm out of the shoulder camera's view
MIN_VISIBLE = 0.5


def measure_scene(seed: int, recognizer: Recognizer | None = None) -> dict[str, Any]:
    """Recognise one scene; returns its object scores, time and false positives."""
    recognizer = recognizer or Recognizer(ObjectLibrary())
    with SimCellSession("perception", seed=seed) as session:
        run(session.sim.robot.move_joints(OBSERVE_JOINTS))
        frame = session.cameras["shoulder"].capture()
        everything = {n: (session.scene.model(n).name, session.truth_pose(n)) for n in
                      session.scene.names()}  # fmt: skip
    truth = {
        name: (model, pose)
        for name, (model, pose) in everything.items()
        if visible_fraction(frame, recognizer.models.get(model), pose) >= MIN_VISIBLE
    }
    # Timed with the simulator closed: its physics thread, stepping as fast as it can,
    # would compete for the two cores and the GIL, and the figure is the recogniser's.
    start = time.perf_counter()
    found = recognizer.recognize(frame)
    seconds = time.perf_counter() - start
    scores = score_recognitions(found, truth, recognizer.models.library)
    return {"scores": scores, "seconds": seconds, "false": _false_positives(found, everything)}


def _false_positives(found: list[Recognition], truth: dict[str, Any]) -> list[str]:
    """Recognitions with no object of their class (visible or not) within 5 cm."""
    return [
        r.object_class
        for r in found
        if not any(
            model == r.object_class and math.dist(r.pose.position, pose.position) < 0.05
            for model, pose in truth.values()
        )
    ]


def summarise(results: list[dict[str, Any]]) -> dict[str, Any]:
    """Recall, median position and rotation errors and plate accuracy over every scene's scores."""
    scores: list[ObjectScore] = [s for r in results for s in r["scores"]]
    found = [s for s in scores if s.found]
    plates = [s for s in scores if s.model.startswith("plate_")]
    return {
        "recall": round(len(found) / max(1, len(scores)), 4),
        "median_pos_err_m": round(statistics.median(s.position_error for s in found), 5),
        "median_rot_err_deg": round(
            math.degrees(statistics.median(s.rotation_error for s in found)), 3
        ),
        "plate_accuracy": round(
            sum(s.nearest_class == s.model for s in plates) / max(1, len(plates)), 4
        ),
        "detect_ms_median": round(1000 * statistics.median(r["seconds"] for r in results), 1),
        "objects": len(scores),
        "plates": len(plates),
        "false_positives": [c for r in results for c in r["false"]],
        "missed": [f"{s.name}" for s in scores if not s.found],
    }


def main() -> None:
    """Run recognition over ``--scenes`` random scenes and print the summary."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=50, help="number of scenes (seeds 0..N-1)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    results, recognizer = [], Recognizer(ObjectLibrary())
    for seed in range(args.scenes):
        result = measure_scene(seed, recognizer)
        results.append(result)
        if not args.json:
            missed = [s.name for s in result["scores"] if not s.found]
            extra = result["false"]
            print(f"seed {seed}: {1000 * result['seconds']:.0f} ms, missed {missed or 'none'}"
                  f"{', false ' + str(extra) if extra else ''}")  # fmt: skip
    summary = summarise(results)
    if args.json:
        keys = ("recall", "median_pos_err_m", "median_rot_err_deg", "plate_accuracy",
                "detect_ms_median")  # fmt: skip
        print(json.dumps({k: summary[k] for k in keys}))
    else:
        for key, value in summary.items():
            print(f"{key}: {value}")


if __name__ == "__main__":
    main()
