"""A run on the simulated cell keeps a thumbnail of each camera about once a second."""

from __future__ import annotations

import base64
import io
import itertools
from pathlib import Path

import cv2
import numpy as np
import pytest

from capabilities.cli import main as costar
from engine.files import save_plan
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.timeline import Timeline
from engine.types import ParamType


@pytest.mark.sim
def test_a_run_on_the_simulated_cell_records_a_picture_of_each_camera_a_second(
    tmp_path: Path,
) -> None:
    wait = NodeSpec(
        NodeKind.WAIT, name="wait", params={"seconds": Binding.fixed(4.0, ParamType.DURATION)}
    )
    plan = tmp_path / "wait.costar.json"
    save_plan(PlanSpec(wait, "wait"), plan)
    runs = tmp_path / "runs"
    out, err = io.StringIO(), io.StringIO()
    argv = ["run", str(plan), "--cell", "sim", "--scene", "cup_to_bin", "--runs", str(runs)]
    assert costar(argv, out, err) == 0, err.getvalue()
    (record,) = runs.iterdir()
    timeline = Timeline.load(record)
    assert timeline.cameras == ["shoulder", "wrist"]
    for camera in timeline.cameras:
        taken = [timeline.picture_time(camera, t / 10) for t in range(0, 60)]
        moments = sorted({t for t in taken if t is not None})
        assert len(moments) >= 2  # the first waits for the live view's mirror to start
        assert all(b - a > 0.9 for a, b in itertools.pairwise(moments))
    pictures = timeline.pictures_at(timeline.duration)
    for jpeg in pictures.values():
        picture = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR)
        assert picture.shape == (120, 160, 3) and picture.std() > 5  # a picture, not a blank
    lines = record.read_text().splitlines()
    assert all(base64.b64decode(line.split('"jpeg":"')[1].split('"')[0]) for line in lines
               if '"thumbnail"' in line)  # fmt: skip
