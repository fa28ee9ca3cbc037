"""The simulated worker: reads the scene file's worker block, hands the bin in and takes it
back at its seeded times, shifts a resting object (checked on ground truth).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import pytest

from capabilities.sim.scene import default_scene_path
from capabilities.sim.scene_spec import SceneFileError, read_scene
from capabilities.sim.session import SimCellSession
from capabilities.sim.worker import SimWorker, parse_worker, plan_events, read_worker
from engine.types import Pose
from tests.capabilities.collaboration.handoff_scene import handoff_scene

STEP = 1.0 / 240.0


def test_the_handoff_scene_has_a_worker_and_still_loads_as_a_scene() -> None:
    path = default_scene_path("handoff")
    assert read_scene(path).name == "handoff"  # the scene parser ignores the worker block
    spec = read_worker(path)
    assert spec is not None
    assert spec.handoffs[0].model == "kit_bin" and spec.handoffs[0].cycles == 2
    assert spec.nudges[0].object == "cup"


def test_a_scene_without_a_worker_block_has_no_worker() -> None:
    assert read_worker(default_scene_path("cup_to_bin")) is None


@pytest.mark.parametrize(
    ("change", "where"),
    [
        ({"place_at": [3.0, 1.0]}, "$.worker.handoffs[0].place_at"),
        ({"cycles": 0}, "$.worker.handoffs[0].cycles"),
        ({"area": {"x": [0.5, 0.6]}}, "$.worker.handoffs[0].area.y"),
    ],
)
def test_a_bad_worker_block_is_refused_with_its_json_path(change: dict, where: str) -> None:
    data = json.loads(default_scene_path("handoff").read_text(encoding="utf-8"))
    data["worker"]["handoffs"][0].update(change)
    with pytest.raises(SceneFileError, match=re.escape(where)):
        parse_worker(data, "test.json")


def test_an_unknown_worker_field_is_refused() -> None:
    with pytest.raises(SceneFileError, match="handoffs, nudges"):
        parse_worker({"worker": {"handoff": []}}, "test.json")


def test_the_schedule_follows_the_seed() -> None:
    spec = read_worker(default_scene_path("handoff"))
    assert spec is not None
    first, again, other = (plan_events(spec, s, 0.0) for s in (5, 5, 6))
    assert first == again and first != other
    kinds = [e.kind for e in first if e.object == "kit_bin"]
    assert kinds == ["placed", "taken", "placed", "taken"]
    offsets = [e.offset for e in first]
    assert offsets == sorted(offsets)


class TruthProbe:
    """GROUND TRUTH after every physics step (a step hook registered after the worker's):
    the simulated time and the object's pose, or None while it is not in the cell.
    """

    def __init__(self, session: SimCellSession, name: str) -> None:
        self.samples: list[tuple[float, Pose | None]] = []
        self._session, self._name = session, name
        self._client = session.sim.call(lambda client: client)
        session.sim.add_step_hook(post=self._sample)

    def _sample(self, now: float) -> None:
        scene = self._session.scene
        present = self._name in scene.objects
        self.samples.append((now, scene.truth_pose(self._client, self._name) if present else None))

    def at(self, time: float) -> Pose | None:
        """The last sample at or before ``time``."""
        before = [pose for t, pose in self.samples if t <= time + 1e-9]
        assert before, f"no sample at or before {time:.3f} s (first at {self.samples[0][0]:.3f})"
        return before[-1]

    def stop(self) -> None:
        self._session.sim.remove_step_hook(post=self._sample)


def run_until(session: SimCellSession, time: float) -> None:
    """Let the simulation run past ``time`` (simulated seconds)."""
    while session.clock() < time:
        session.sim.wait_sim(0.25)


def start_worker(
    tmp_path: Path, seed: int, nudges: bool = False, **handoff: Any
) -> tuple[SimCellSession, SimWorker, TruthProbe]:
    """A session of the handoff scene whose worker starts after a probe of ``handoff``'s
    object is in place (the simulation runs as fast as it can: a worker made with the
    session could act before the test's probe is there).
    """
    spec = read_worker(handoff_scene(tmp_path, nudges, **handoff))
    assert spec is not None
    session = SimCellSession(handoff_scene(tmp_path, worker=False), seed, speed=None)
    probe = TruthProbe(session, "cup" if nudges else "kit_bin")
    worker = SimWorker(spec, session.scene, seed)
    worker.install(session.sim)
    return session, worker, probe


def test_the_worker_places_and_takes_the_bin_at_its_seeded_times(tmp_path: Path) -> None:
    session, worker, probe = start_worker(
        tmp_path, 11, place_at=[0.3, 0.6], hold=[0.5, 0.8], cycles=2, gap=[0.3, 0.5]
    )
    with session:
        planned = [(t, k) for t, k, name in worker.planned_times() if name == "kit_bin"]
        assert [k for _, k in planned] == ["placed", "taken", "placed", "taken"]
        run_until(session, planned[-1][0] + 0.1)
        probe.stop()
        events = worker.events()
        assert [e.kind for e in events] == ["placed", "taken", "placed", "taken"]
        for event, (time, _) in zip(events, planned, strict=True):
            assert abs(event.time - time) <= STEP + 1e-9  # acted at the step of its time
        for (put, _), (took, _) in (planned[0:2], planned[2:4]):
            assert probe.at(put - 0.01) is None  # not there before the place
            settled = probe.at(took - 0.01)  # there, on the table, until taken
            assert settled is not None
            assert abs(settled.position[2] - session.scene.table_top_z) < 0.003
            assert probe.at(took + 0.01) is None
        placed, settled = events[0].pose, probe.at(planned[1][0] - 0.01)
        assert placed is not None and settled is not None
        assert math.dist(settled.position[:2], placed.position[:2]) < 0.005


def test_the_worker_shifts_the_resting_cup(tmp_path: Path) -> None:
    session, worker, probe = start_worker(tmp_path, 2, nudges=True, place_at=[30.0, 30.0])
    with session:
        when = next(t for t, kind, _ in worker.planned_times() if kind == "moved")
        run_until(session, when + 0.5)
        probe.stop()
        moved = [e for e in worker.events() if e.kind == "moved"]
        assert len(moved) == 1 and moved[0].object == "cup"
        before, after = probe.at(when - 0.01), probe.at(when + 0.5)
        assert before is not None and after is not None
        shift = math.dist(before.position[:2], after.position[:2])
        low, high = worker.spec.nudges[0].shift
        assert low - 0.003 <= shift <= high + 0.003
        assert abs(after.position[2] - session.scene.table_top_z) < 0.003  # still standing


def test_a_session_without_a_worker_block_has_none() -> None:
    with SimCellSession("cup_to_bin", 0, speed=None) as session:
        assert session.worker is None
        assert "operator" in session.interfaces()
