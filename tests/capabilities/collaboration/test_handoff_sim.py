"""wait_for_handoff and object_in_region on the simulated cell: the simulated worker puts the
kit bin down; the operation sees it by its markers in the shoulder camera's images.

Ground truth (the worker's events, the bin's true pose) is used only to score.
"""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from capabilities.base import CapabilityRegistry
from capabilities.collaboration import capability
from capabilities.collaboration.handoff import (
    HandoffJob,
    HandoffSettings,
    find_object,
    object_markers,
    region_crop,
)
from capabilities.sim.session import SimCellSession
from engine.build import build_tree
from engine.executor import run_to_end
from engine.spec import Binding, NodeKind, NodeSpec, PlanSpec
from engine.status import Status
from engine.tree import BehaviorTree
from engine.types import ObjectModel, ParamType, Pose, Region
from tests.capabilities.collaboration.handoff_scene import handoff_scene

HANDOFF_AREA = Region((0.56, 0.27, 0.0), 0.1)  # around the scene's handoff area
DEADLINE = 90.0  # generous wall-clock bound of a run; never the measured outcome
# The latency is measured in simulated time from the worker's placing to the stamp of the
# camera frame the operation decided on (its detection in the world model): the operation's
# own latency (poll interval, settling), not how fast this machine delivers events. The
# simulation runs at half real time, so that a poll thread woken late on a loaded machine
# costs half as much simulated time.
LATENCY_SPEED = 0.5


def handoff_node(name: str = "handoff", **params: Any) -> NodeSpec:
    bindings = {
        "object": Binding.fixed(ObjectModel("kit_bin"), ParamType.OBJECT),
        "region": Binding.fixed(HANDOFF_AREA, ParamType.REGION),
        "timeout": Binding.fixed(30.0, ParamType.DURATION),
        "pose": Binding.reference("BIN_POSE"),
    }
    for port, value in params.items():
        bindings[port] = Binding.fixed(value, ParamType.DURATION)
    return NodeSpec(NodeKind.OPERATION, name=name, op="collaboration.wait_for_handoff",
                    params=bindings)  # fmt: skip


def in_region_node() -> NodeSpec:
    return NodeSpec(NodeKind.OPERATION, name="bin there", op="collaboration.object_in_region",
                    params={"object": Binding.fixed(ObjectModel("kit_bin"), ParamType.OBJECT),
                            "region": Binding.fixed(HANDOFF_AREA, ParamType.REGION)})  # fmt: skip


def close_to_truth(seen: Pose, placed: Pose | None) -> None:
    """Seen where the worker put it (GROUND TRUTH: its pose on the table); it may have been
    seen while still dropping the last centimetre.
    """
    assert placed is not None
    assert math.dist(seen.position[:2], placed.position[:2]) < 0.01
    assert abs(seen.position[2] - placed.position[2]) < 0.015


def build(session: SimCellSession, root: NodeSpec) -> BehaviorTree:
    registry = CapabilityRegistry([capability()], cell=session)
    return build_tree(PlanSpec(root, "handoff"), registry, clock=session.clock)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_handoff_is_seen_within_half_a_second_of_cell_time(tmp_path: Path, seed: int) -> None:
    path = handoff_scene(tmp_path, place_at=[0.4, 0.9], hold=[1000.0, 1000.0])
    with SimCellSession(path, seed, speed=LATENCY_SPEED) as session:
        tree = build(session, handoff_node())
        result = run_to_end(tree, 20.0, DEADLINE)
        assert result.status is Status.SUCCESS, tree.root.message
        assert session.worker is not None
        placed = [e for e in session.worker.events() if e.kind == "placed"]  # ground truth
        assert len(placed) == 1
        decided = session.world_model.best("kit_bin")  # the frame the operation decided on
        assert decided is not None and decided.source.startswith("collaboration:")
        latency = decided.stamp - placed[0].time
        print(f"seed {seed}: handoff seen {latency:.3f} s of cell time after it was placed")
        assert 0.0 <= latency < 0.5  # 0: the frame of the very step it was put down
        seen = tree.blackboard.get("BIN_POSE")
        close_to_truth(seen, placed[0].pose)


def test_the_handoff_is_written_to_the_world_model_and_the_region_check_agrees(
    tmp_path: Path,
) -> None:
    path = handoff_scene(tmp_path, place_at=[0.5, 0.6], hold=[1000.0, 1000.0])
    with SimCellSession(path, 3, speed=None) as session:
        root = NodeSpec(NodeKind.SEQUENCE, name="steps",
                        children=[handoff_node(settle=0.2), in_region_node()])  # fmt: skip
        tree = build(session, root)
        result = run_to_end(tree, 20.0, DEADLINE)
        assert result.status is Status.SUCCESS, [n.message for n in tree.iterate()]
        detection = session.world_model.best("kit_bin")
        assert detection is not None and detection.source == "collaboration:shoulder"
        assert session.worker is not None
        placed = session.worker.events()[0]
        assert detection.stamp >= placed.time + 0.2  # put down, then lay still
        close_to_truth(detection.pose, placed.pose)


def test_an_object_seen_elsewhere_is_not_in_the_region_and_no_handoff_there(
    tmp_path: Path,
) -> None:
    path = handoff_scene(tmp_path, place_at=[0.3, 0.3], hold=[1000.0, 1000.0])
    elsewhere = Region((0.45, -0.3, 0.0), 0.1)
    with SimCellSession(path, 4, speed=None) as session:
        assert run_to_end(build(session, handoff_node()), 20.0, DEADLINE).status is Status.SUCCESS
        check = in_region_node()
        check.params["region"] = Binding.fixed(elsewhere, ParamType.REGION)
        assert run_to_end(build(session, check), 20.0, DEADLINE).status is Status.FAILURE
        watch = handoff_node(timeout=1.0)
        watch.params["region"] = Binding.fixed(elsewhere, ParamType.REGION)
        tree = build(session, watch)
        assert run_to_end(tree, 20.0, DEADLINE).status is Status.FAILURE
        assert tree.root.message.startswith("timed out")


def test_halting_the_wait_takes_no_more_frames(tmp_path: Path) -> None:
    with SimCellSession("cup_to_bin", 0, speed=None) as session:
        library = session.scene.library
        frames = threading.Event()

        class CountingCamera:
            name, on_wrist = "shoulder", False

            def capture(self) -> Any:
                frames.set()
                return session.cameras["shoulder"].capture()

        job = HandoffJob(CountingCamera(), object_markers(library.get("kit_bin")),  # type: ignore[arg-type]  # a duck-typed camera
                         HANDOFF_AREA, session.world_model, session.clock,
                         HandoffSettings(), session.workers)  # fmt: skip
        deadline = time.monotonic() + DEADLINE
        while not frames.is_set() and time.monotonic() < deadline:
            assert job.poll() is Status.RUNNING  # the engine polls it at every tick
            time.sleep(0.01)
        assert frames.is_set()
        job.cancel()
        taken = job.frames
        for _ in range(20):
            assert job.poll() is Status.FAILURE and job.message == "halted"
            session.sim.wait_sim(0.2)
        assert job.frames <= taken + 1  # at most the frame under way when it was halted


def test_searching_only_the_regions_part_of_the_image_finds_the_same_pose() -> None:
    with SimCellSession("kitting", 0, speed=None) as session:
        target = object_markers(session.scene.library.get("kit_bin"))
        frame = session.cameras["shoulder"].capture()
        whole = find_object(frame, target, "test")
        assert whole is not None
        region = Region(whole.pose.position, 0.1)
        box = region_crop(frame, region, target.reach)
        assert box is not None
        x0, y0, x1, y1 = box
        assert (x1 - x0) * (y1 - y0) < 0.6 * frame.rgb.shape[0] * frame.rgb.shape[1]
        cropped = find_object(frame, target, "test", region)
        assert cropped is not None and cropped.instance == whole.instance
        assert math.dist(cropped.pose.position, whole.pose.position) < 0.001
