"""A copy of ``resources/scenes/handoff.json`` with a quicker worker, for tests."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from capabilities.sim.scene import default_scene_path

__all__ = ["handoff_scene"]


def handoff_scene(folder: Path, nudges: bool = False, worker: bool = True, **handoff: Any) -> Path:
    """Write the handoff scene with its first handoff changed by ``handoff`` (e.g.
    ``place_at=[0.5, 1.0]``); nudges are dropped unless asked for, the whole worker block
    when ``worker`` is False. Returns the path.
    """
    data = json.loads(default_scene_path("handoff").read_text(encoding="utf-8"))
    first = data["worker"]["handoffs"][0]
    first.update({"place_at": [0.5, 1.2], "hold": [1.0, 1.5], "cycles": 1})
    first.update(handoff)
    if not nudges:
        data["worker"]["nudges"] = []
    if not worker:
        del data["worker"]
    path = folder / ("handoff_test.json" if worker else "handoff_no_worker.json")
    path.write_text(json.dumps(data), encoding="utf-8")
    return path
